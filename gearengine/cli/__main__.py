"""``python -m gearengine.cli``: the ``gearengine`` command."""

from gearengine.cli.main import command

command()
