"""`python -m oit`: see oit.cli."""

from .cli import main

raise SystemExit(main())
