"""``python -m trms.cli``: the ``trms`` command."""

import sys

from trms.cli import main

if __name__ == "__main__":
    sys.exit(main())
