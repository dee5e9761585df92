"""The cli room: the engine's commands (melnikov, analyze, check, sweep, convert) on top of every
other room; ``command`` (``main``, then exit) is the ``gearengine`` console script. Imports no
web code."""

from gearengine.cli.main import command, main

__all__ = ["command", "main"]
