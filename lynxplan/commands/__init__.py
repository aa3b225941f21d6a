"""CLI sub-commands, one module each; see :mod:`lynxplan.cli`."""
