"""``python -m aerostat_gym.cli``: the same as the ``aerostat-gym`` command."""

import sys

from . import main

sys.exit(main())
