"""File reads and writes overlapped on threads, results taken in order.

OpenImageIO's decoders and encoders release the GIL, so several files are
read or written at once on several cores (and alongside numpy or numba work,
which release it too). :func:`in_order` keeps the callers' sequential
contracts: results come back in the order the tasks were given, the first
failure (in that order) is the one raised, and a task starts only after the
consumer took the result ``window`` places before it, so a consumer that stops
(a cancel raised from a progress callback, or an error) starts nothing more.
At most ``window`` tasks, each with its image in memory, are in flight.
"""

from __future__ import annotations

import os
from collections import deque
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import Future, ThreadPoolExecutor
from typing import TypeVar

T = TypeVar("T")

#: files in flight at once: two where there are two cores. A set's largest file
#: dominates, so more would gain little, hold more images in memory and make a
#: cancel wait for more files
WINDOW = 2 if (os.cpu_count() or 1) > 1 else 1


def in_order(tasks: Sequence[Callable[[], T]], window: int = WINDOW) -> Iterator[T]:
    """Run ``tasks`` on up to ``window`` threads; yield their results in order.

    Stopping the iteration early (``close``, or an exception in the consumer)
    cancels nothing that runs, but waits for it and starts nothing new; a task's
    exception is raised when its result is reached, after the running tasks end.
    """
    if window <= 1 or len(tasks) <= 1:
        for task in tasks:
            yield task()
        return
    with ThreadPoolExecutor(max_workers=min(window, len(tasks))) as pool:
        running: deque[Future[T]] = deque()
        upcoming = iter(tasks)
        for task in upcoming:
            running.append(pool.submit(task))
            if len(running) == window:
                break
        try:
            while running:
                result = running.popleft().result()
                yield result
                task = next(upcoming, None)
                if task is not None:
                    running.append(pool.submit(task))
        finally:
            for future in running:
                future.cancel()
