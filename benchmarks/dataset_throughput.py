"""Synthetic dataset generation: clips per minute with the local process pool (1 and 2
processes) and on a Dask LocalCluster of 2 single-threaded workers.

Run: ``PYTHONPATH=. python benchmarks/dataset_throughput.py [--clips 8] [--size 128]``.
Each clip is 1 s at 25 fps, rendered to PNG frames with labels and landmarks. The figures
include starting the worker processes (and the cluster's scheduler and workers), as a user
running ``facelib dataset`` sees them.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from machine import describe

from facelib.dataset import DatasetSpec, generate


def _spec(clips: int, size: int) -> DatasetSpec:
    return DatasetSpec(clips=clips, seed=1, seconds=1.0, width=size, height=size,
                       behaviours=("default", "distress", "ironic"),
                       texts=("Hello there, how are you?", "Synthetic faces at scale."))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--clips", type=int, default=8)
    parser.add_argument("--size", type=int, default=128)
    args = parser.parse_args()
    spec = _spec(args.clips, args.size)
    print(f"machine: {describe()}")
    print(f"dataset: {args.clips} clips of 1 s (25 frames) at {args.size}x{args.size}, PNG")
    with tempfile.TemporaryDirectory() as tmp:
        for jobs in (1, 2):
            started = time.perf_counter()
            generate(spec, Path(tmp) / f"local{jobs}", jobs=jobs)
            seconds = time.perf_counter() - started
            print(f"local pool, {jobs} process(es): {seconds:6.1f} s, "
                  f"{args.clips / seconds * 60:6.1f} clips/min")
        from distributed import LocalCluster

        started = time.perf_counter()
        with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                          dashboard_address=None) as cluster:
            generate(spec, Path(tmp) / "dask", scheduler=cluster.scheduler_address)
        seconds = time.perf_counter() - started
        print(f"Dask LocalCluster, 2 workers:  {seconds:6.1f} s, "
              f"{args.clips / seconds * 60:6.1f} clips/min (cluster start included)")


if __name__ == "__main__":
    main()
