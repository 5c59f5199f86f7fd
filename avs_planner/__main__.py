import sys

from avs_planner.cli import main

sys.exit(main())
