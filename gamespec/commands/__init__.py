"""Command groups that register in the ``gamespec.commands`` entry-point group."""
