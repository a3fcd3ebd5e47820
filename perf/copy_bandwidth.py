#!/usr/bin/env python3
"""Copy bandwidth of this machine, the floor of a memory-bound kernel: np.copyto of a 256 MiB array, counted as
read + write bytes, median of 7, on one core and on every core at once (one process per core, each its own
arrays). Prints one JSON object; GB_per_s is the all-cores figure."""
import json
import multiprocessing as mp
import os
import statistics
import time

import numpy as np


def one_core(n_bytes=256 << 20, repeats=7):
    a = np.ones(n_bytes // 8)
    b = np.empty_like(a)
    np.copyto(b, a)
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        np.copyto(b, a)
        times.append(time.perf_counter() - start)
    return 2 * n_bytes / statistics.median(times) / 1e9


def worker(_):
    return one_core()


if __name__ == "__main__":
    single = one_core()
    cores = os.cpu_count() or 1
    with mp.Pool(cores) as pool:
        each = pool.map(worker, range(cores))
    print(json.dumps({"GB_per_s": sum(each), "one_core_GB_per_s": single, "cores": cores,
                      "note": f"np.copyto 256 MiB, read+write, {cores} processes at once; one core {single:.3g} GB/s"}))
