"""The ``cyclecoord`` command line: one entry point, one subcommand per job."""

from .main import main

__all__ = ["main"]
