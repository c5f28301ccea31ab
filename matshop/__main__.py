"""``python -m matshop``: the same as the ``matshop`` command."""

from .cli import main

raise SystemExit(main())
