"""Loading and turning the artist's lighting environment: what the editor's worker does.

    python benchmarks/environment.py [--repeat 3] [--rows 2048]

Data: a synthetic equirect float HDR of ``--rows`` x ``2 rows`` (a sky gradient with a
sun), written to a temporary folder with OpenImageIO. Ours:
:meth:`EnvironmentChoice.load` (read, reduce to 1024 rows, prefilter: the mip chain and
the irradiance map) and a new turn of the loaded map (:meth:`EnvironmentChoice.turn`:
roll and prefilter again). Baselines, in the same process: OpenImageIO's plain read of
the same file into a float32 numpy array (what any viewer must pay) for the load, the
load itself for a turn. Wall time and
the process's CPU time (``time.process_time``) are both printed: the machine is shared,
and NUMBA_NUM_THREADS=1 and OpenCV's one thread keep the work on one core.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import cv2  # noqa: E402
import numpy as np  # noqa: E402
import OpenImageIO as oiio  # noqa: E402
from _common import goal  # noqa: E402

from matshop.render.environment_choice import EnvironmentChoice  # noqa: E402


def write_sky(path: Path, rows: int) -> Path:
    theta = (np.arange(rows) + 0.5) / rows * np.pi
    sky = np.repeat(np.cos(theta).clip(0.05, None)[:, None], 2 * rows, axis=1)
    image = np.repeat(sky[..., None], 3, axis=2).astype(np.float32)
    image[rows // 7 : rows // 7 + rows // 50, rows // 2 : rows // 2 + rows // 50] = 200.0
    spec = oiio.ImageSpec(2 * rows, rows, 3, "float")
    out = oiio.ImageOutput.create(str(path))
    out.open(str(path), spec)
    out.write_image(image)
    out.close()
    return path


def plain_read(path: Path) -> np.ndarray:
    image = oiio.ImageInput.open(str(path))
    pixels = image.read_image(0, 0, 0, 3, "float")
    image.close()
    return np.asarray(pixels, dtype=np.float32)


def timed(fn) -> tuple[float, float]:
    wall, cpu = time.perf_counter(), time.process_time()
    fn()
    return time.perf_counter() - wall, time.process_time() - cpu


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--rows", type=int, default=2048)
    args = parser.parse_args()
    cv2.setNumThreads(1)
    print(f"load average {os.getloadavg()[0]:.1f}; {2 * args.rows}x{args.rows} float HDR")
    with tempfile.TemporaryDirectory() as folder:
        path = write_sky(Path(folder) / "sky.hdr", args.rows)
        choice = EnvironmentChoice.parse(path, 0.0)
        turned = choice.changed(rotation_deg=90.0)
        base = choice.load_base()  # warm-up (numba, cv2, page cache)
        plain_read(path)
        load_ratios, turn_ratios = [], []
        for _ in range(args.repeat):
            read_wall, read_cpu = timed(lambda: plain_read(path))
            load_wall, load_cpu = timed(lambda: choice.load())
            turn_wall, turn_cpu = timed(lambda: turned.turn(base))
            print(
                f"plain read {1000 * read_wall:.0f} ms ({1000 * read_cpu:.0f} CPU); "
                f"load {1000 * load_wall:.0f} ms ({1000 * load_cpu:.0f} CPU); "
                f"a new turn {1000 * turn_wall:.0f} ms ({1000 * turn_cpu:.0f} CPU)"
            )
            load_ratios.append(load_cpu / read_cpu)
            turn_ratios.append(turn_cpu / load_cpu)
    # the load reads the file once, reduces it and prefilters a 1024-row map: a few reads
    goal("environment load / plain read (CPU)", load_ratios, 4.0)
    # a new turn skips the read and the reduction: cheaper than loading again
    goal("environment turn / load (CPU)", turn_ratios, 1.0, strict=True)


if __name__ == "__main__":
    main()
