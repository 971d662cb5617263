"""``python -m urdsl``: the same as the ``urdsl`` command."""

import sys

from .cli import main

if __name__ == "__main__":
    sys.exit(main())
