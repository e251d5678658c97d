"""Subcommands of the ``sid`` command line, one module each."""
