"""`python -m oit.bench`: see oit.bench.cli."""

from .cli import main

raise SystemExit(main())
