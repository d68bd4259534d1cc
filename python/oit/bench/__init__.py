"""The benchmark (`python -m oit bench`), in layers; a module imports only those below it:

- `harness`: what runs (parameter sets, scenes at their sizes), timing, progress, errors
  against the exact image, tables. It imports nothing of oit.bench.
- `results`: the main sweep, every method (and the peers) on every scene (results.csv, .md).
- `figure7`, `temporal`, `auto`, `antialias`, `scale`: the experiments, each on the harness alone.
- `cli`: the command line, over all of them (`__main__` runs it).

This file imports none of them, so `import oit.bench.harness` loads the harness only."""
