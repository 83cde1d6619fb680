"""``python -m ccproof.cli``: the same as the ``ccproof`` command."""

import sys

from ccproof.cli import main

sys.exit(main())
