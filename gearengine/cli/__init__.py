"""The cli room: the engine's commands (melnikov, analyze, check, sweep, convert) on top of every
other room; ``main`` is the ``gearengine`` console script. Imports no web code."""

from gearengine.cli.main import main

__all__ = ["main"]
