"""``python -m facsim``: the command line."""
import sys


def run(argv=None) -> int:
    """The ``facsim`` command line (imported only when it runs)."""
    from facsim.cli import main

    return main(argv)


if __name__ == "__main__":
    sys.exit(run())
