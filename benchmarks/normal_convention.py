"""Calibration of the normal-map convention guess: accuracy against confidence.

Writes the generated corpus (``tests/normal_corpus.py``: height fields baked
to normals in both conventions, tiled or in UV islands, PNG 8/16 bit and JPEG
q50-95, 256-4096 texels) into a folder, reads every map back as a load does,
guesses, and prints:

* accuracy per confidence bin, the fraction of maps at or above
  ``CONFIDENT_GUESS`` and every wrong guess at or above it (there must be none);
* the same per family and per encoding;
* the guess's time per size, as a ratio to decoding the same map
  (``decode_normal_map``, which every load does anyway), measured in this run;
* real maps: the shared chessboard set's normal map, and any folder given with
  ``--real DIR`` (maps whose convention is ``--real-convention``), each also
  with its green channel flipped.

    python benchmarks/normal_convention.py [--quick] [--corpus DIR] [--real DIR]
                                           [--seed-offset N]

The full corpus takes ~20 minutes to write on two cores; ``--corpus DIR``
keeps it and reuses the files already there. Exit status 1 when a confident
guess is wrong.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path

import numpy as np
from _common import CHESSBOARD

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from normal_corpus import MapSpec, ci_specs, full_specs, read_map, write_corpus  # noqa: E402

from matshop.spaces.frame import (  # noqa: E402
    CONFIDENT_GUESS,
    decode_normal_map,
    guess_normal_convention,
)

BINS = (0.0, 0.05, 0.1, 0.25, 0.5, 0.75, 0.9, 0.99, 1.0)


def run_corpus(specs: list[MapSpec], folder: Path) -> list[tuple[MapSpec, str, float, float]]:
    """(spec, guess, confidence, seconds) per map; files already in ``folder`` are reused."""
    todo = [s for s in specs if not (folder / s.name).exists()]
    if todo:
        print(f"writing {len(todo)} maps into {folder} ...", file=sys.stderr)
        for _ in write_corpus(todo, folder):
            pass
    results = []
    for spec in specs:
        rgb = read_map(folder / spec.name)
        start = time.perf_counter()
        guess, confidence = guess_normal_convention(rgb)
        results.append((spec, guess, confidence, time.perf_counter() - start))
    return results


def print_bins(results: list[tuple[MapSpec, str, float, float]]) -> None:
    print(f"{'confidence':>14s} {'maps':>6s} {'right':>6s} {'accuracy':>9s}")
    for lo, hi in zip(BINS[:-1], BINS[1:], strict=True):
        rows = [r for r in results if lo <= r[2] < hi or (hi == 1.0 and r[2] == 1.0)]
        right = sum(r[1] == r[0].convention for r in rows)
        acc = f"{right / len(rows):9.3f}" if rows else f"{'-':>9s}"
        print(f"  [{lo:4.2f}, {hi:4.2f}) {len(rows):6d} {right:6d} {acc}")


def print_groups(results, key, title: str) -> None:
    groups = defaultdict(list)
    for r in results:
        groups[key(r[0])].append(r)
    print(f"\n{title:>12s} {'maps':>5s} {'accuracy':>9s} {'confident':>10s} {'wrong conf.':>12s}")
    for name in sorted(groups):
        rows = groups[name]
        acc = np.mean([r[1] == r[0].convention for r in rows])
        confident = [r for r in rows if r[2] >= CONFIDENT_GUESS]
        wrong = sum(r[1] != r[0].convention for r in confident)
        share = len(confident) / len(rows)
        print(f"{name:>12s} {len(rows):5d} {acc:9.3f} {share:10.2f} {wrong:12d}")


def print_speed(results, folder: Path) -> None:
    print(f"\n{'size':>6s} {'guess ms':>9s} {'decode ms':>10s} {'ratio':>6s}")
    for size in sorted({r[0].size for r in results}):
        rows = [r for r in results if r[0].size == size]
        rgb = read_map(folder / rows[0][0].name)
        start = time.perf_counter()
        decode_normal_map(rgb)
        decode = time.perf_counter() - start
        guess = statistics.median(r[3] for r in rows)
        print(f"{size:6d} {guess * 1e3:9.1f} {decode * 1e3:10.1f} {guess / decode:6.2f}")


def print_real(paths: list[Path], convention: str) -> None:
    print(f"\nreal maps (known {convention}); columns: guess, confidence, and with green flipped")
    for path in paths:
        rgb = read_map(path)
        flipped = rgb.copy()
        flipped[..., 1] = 1.0 - flipped[..., 1]
        guess, confidence = guess_normal_convention(rgb)
        guess_f, confidence_f = guess_normal_convention(flipped)
        mark = (
            "" if confidence < CONFIDENT_GUESS else "  right" if guess == convention else "  WRONG"
        )
        flip = f"{guess_f:8s} {confidence_f:.3f}"
        print(f"  {path.name:32s} {guess:8s} {confidence:.3f}   {flip}{mark}")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the CI corpus only (66 small maps)")
    parser.add_argument("--corpus", type=Path, help="folder to write (and reuse) the corpus in")
    parser.add_argument(
        "--real", type=Path, action="append", default=[], help="folder of real maps"
    )
    parser.add_argument(
        "--seed-offset", type=int, default=0, help="a fresh corpus of the same make-up"
    )
    parser.add_argument("--real-convention", default="opengl", choices=("opengl", "directx"))
    args = parser.parse_args()
    specs = ci_specs() if args.quick else full_specs(args.seed_offset)
    with tempfile.TemporaryDirectory() as tmp:
        folder = args.corpus or Path(tmp)
        folder.mkdir(parents=True, exist_ok=True)
        results = run_corpus(specs, folder)
        confident = [r for r in results if r[2] >= CONFIDENT_GUESS]
        wrong = [r for r in confident if r[1] != r[0].convention]
        worst = max((r[2] for r in results if r[1] != r[0].convention), default=0.0)
        print(f"{len(results)} maps; CONFIDENT_GUESS = {CONFIDENT_GUESS}")
        print_bins(results)
        share = len(confident) / len(results)
        print(
            f"\nconfident: {len(confident)} of {len(results)} ({share:.1%}),"
            f" wrong among them: {len(wrong)}; largest confidence of a wrong guess: {worst:.3f}"
        )
        for spec, guess, confidence, _ in wrong:
            print(f"  WRONG {spec.name}: {guess} at {confidence:.3f}")
        print_groups(results, lambda s: s.family, "family")
        print_groups(results, lambda s: s.encoding, "encoding")
        print_groups(results, lambda s: str(s.size), "size")
        print_speed(results, folder)
    if CHESSBOARD.is_dir():  # MaterialX's chess set, OpenGL like its glTF source
        print_real([CHESSBOARD / "chessboard_normal.jpg"], "opengl")
    for extra in args.real:
        maps = sorted(p for p in extra.iterdir() if p.suffix.lower() in (".png", ".jpg", ".tif"))
        print_real(maps, args.real_convention)
    return 1 if wrong else 0


if __name__ == "__main__":
    sys.exit(main())
