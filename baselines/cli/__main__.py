"""``python -m baselines.cli``: the ``shipgym`` console script."""

import sys

from baselines.cli import main

sys.exit(main())
