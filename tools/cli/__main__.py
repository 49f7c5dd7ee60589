"""``python -m tafel.tools.cli``: the ``tafel`` command."""

import sys

from tafel.tools.cli.dispatch import main

sys.exit(main())
