"""The ``matshop`` command.

Every verb is a thin shell over the same engine the editor uses. This module
parses the command line (the verbs are listed in :mod:`.registry` and imported
only when named), runs the one verb, and is the one place that turns a user
error into one line and exit status 2; nothing is written when a command fails.
"""

from __future__ import annotations

import argparse
import gc
import importlib.util
import os
import sys
from collections.abc import Iterator, Sequence
from contextlib import contextmanager

from .. import __version__
from ..errors import MatshopError
from .registry import VERBS, load

EXIT_USAGE = 2

_DESCRIPTION = """\
matshop edits spatially-varying materials (texture sets) in editing spaces,
where plain image operations respect what each parameter means.

examples:
  matshop info path/to/textures/            what is in a texture set
  matshop convert in/ out/                  import -> edit space -> back -> write
  matshop convert in/ out/ --sampled-distribution
                                            replace GGX roughness by a sampled
                                            128-bin microfacet distribution (EXR)
  matshop demo                              the headless pipeline on the bundled sample
"""


def _has_display() -> bool:
    """Whether a bare ``matshop`` can open a window (else it prints its help)."""
    if sys.platform in ("darwin", "win32"):
        return True
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def build_parser(argv: Sequence[str] = ()) -> argparse.ArgumentParser:
    """The parser of ``matshop``: every verb listed, the options of the one ``argv`` names.

    ``matshop`` has no option that takes a value, so the verb is the first word
    that is not an option.
    """
    parser = argparse.ArgumentParser(
        prog="matshop",
        description=_DESCRIPTION,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"matshop {__version__}")
    verbs = parser.add_subparsers(dest="verb", metavar="COMMAND")
    named = next((word for word in argv if not word.startswith("-")), None)
    for name, verb in VERBS.items():
        subparser = verbs.add_parser(name, help=verb.summary, description=verb.summary)
        if name == named:
            load(name).add_arguments(subparser)
    return parser


@contextmanager
def _fewer_collections() -> Iterator[None]:
    """The cyclic collector runs every 50 000 allocations instead of 700 while a verb runs.

    A verb's start-up (numpy, numba and its compiler target, OpenImageIO, cv2)
    makes ~10^5 objects that live until the process ends, and the default
    thresholds walk them again and again: ~0.1 s of CPU of `matshop apply`
    (measured). Cycles are still collected. Restored afterwards: tests and
    scripts call main() inside their own process.
    """
    thresholds = gc.get_threshold()
    gc.set_threshold(50_000, *thresholds[1:])
    try:
        yield
    finally:
        gc.set_threshold(*thresholds)


def main(argv: Sequence[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = build_parser(argv)
    args = parser.parse_args(argv)
    if args.verb is None:
        if _has_display() and importlib.util.find_spec("PySide6") is not None:
            from ..app import launch

            return launch.start()
        parser.print_help()
        return EXIT_USAGE
    try:
        with _fewer_collections():
            return args.run(args)
    except MatshopError as exc:
        print(f"matshop: error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt:
        print("matshop: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # `matshop info | head`: quiet exit, no traceback
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
