"""``python -m facsim``: the command line."""
import sys

from facsim.cli import main

sys.exit(main())
