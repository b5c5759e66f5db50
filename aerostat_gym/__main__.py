"""``python -m aerostat_gym``: the same as the ``aerostat-gym`` command."""

import sys

from .cli import main

sys.exit(main())
