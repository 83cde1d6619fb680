"""``python -m ccproof.cli``: the same as the ``ccproof`` command."""

import sys

from ccproof.cli import main

if __name__ == "__main__":
    sys.exit(main())
