"""``python -m signorini.cli``: the ``signorini`` command."""

import sys

from . import main

sys.exit(main())
