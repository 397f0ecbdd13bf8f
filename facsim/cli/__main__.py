"""``python -m facsim.cli``: the command line (same as ``python -m facsim``)."""
import sys

from facsim.cli import main

sys.exit(main())
