"""``python -m shipgym_baselines.cli``: the ``shipgym`` console script."""

import sys

from shipgym_baselines.cli import main

sys.exit(main())
