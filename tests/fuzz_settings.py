"""How long the fuzzers run: seconds each in CI, far longer with ``pytest --long``.

``pytest --long`` (or ``MATSHOP_FUZZ_LONG=1``) multiplies every fuzzer's
example count by :data:`LONG_FACTOR` (``MATSHOP_FUZZ_FACTOR`` overrides it);
run with ``--hypothesis-show-statistics`` to see the counts.
"""

from __future__ import annotations

import os

LONG_FACTOR = int(os.environ.get("MATSHOP_FUZZ_FACTOR", "50"))


def long_mode() -> bool:
    return os.environ.get("MATSHOP_FUZZ_LONG", "") not in ("", "0")


def fuzz_examples(ci: int) -> int:
    """``ci`` examples in a normal run, ``ci * LONG_FACTOR`` in long mode."""
    return ci * LONG_FACTOR if long_mode() else ci
