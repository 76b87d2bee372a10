"""`python -m mtt_sim.cli`: the `mtt-sim` command."""

import sys

from mtt_sim.cli import main

sys.exit(main())
