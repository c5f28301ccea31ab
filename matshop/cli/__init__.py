"""The ``matshop`` command.

Every verb is a thin shell over the same engine the editor uses. This module
parses the command line (the verbs are listed in :mod:`.registry` and imported
only when named), runs the one verb, and is the one place that turns a user
error into one line and exit status 2; nothing is written when a command fails.
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import sys
from collections.abc import Sequence

from .. import __version__
from ..errors import MatshopError
from ..kernel_cache import cached_kernels_without_compiler_set_up
from .registry import VERBS, load
from .startup import fewer_collections, numba_without_unused_extras

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


def main(argv: Sequence[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    with fewer_collections():  # a verb's module imports the engine while it is parsed
        parser = build_parser(argv)
        args = parser.parse_args(argv)
        if args.verb is not None:
            return _run(args)
    # no verb: the editor, whose long session keeps Python's default collector
    if _has_display() and importlib.util.find_spec("PySide6") is not None:
        from ..app import launch

        return launch.start()
    parser.print_help()
    return EXIT_USAGE


def _run(args: argparse.Namespace) -> int:
    """Run the verb ``args`` names; a user error is one line and exit status 2."""
    numba_without_unused_extras()
    try:
        with cached_kernels_without_compiler_set_up():
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
