"""``python -m gearengine.cli``: the ``gearengine`` command."""

import sys

from gearengine.cli.main import main

sys.exit(main())
