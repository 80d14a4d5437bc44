"""Precompute a collection's per-shape stage on a Dask LocalCluster, then co-segment it warm.

    python examples/python/dask_collection.py collections/chairs -o /tmp/chairs-out
    python examples/python/dask_collection.py collections/chairs --bench 3   # 1 vs 2 workers, median of 3

The same code runs on a real cluster: replace the LocalCluster by a dask-jobqueue SLURMCluster
or a dask-kubernetes KubeCluster (see docs/PYTHON.md).
"""

import argparse
import os
import shutil
import statistics
import tempfile
import time

from dask.distributed import Client, LocalCluster

import coseg
import coseg.dask


def precompute_on(folder, workers, cache_dir, options):
    """Wall time of the per-shape stage on a fresh `workers`-process LocalCluster (cluster
    start-up excluded), and its report."""
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with Client(cluster) as client:
            client.wait_for_workers(workers)
            t = time.perf_counter()
            report = coseg.dask.precompute(folder, client, cache_dir, **options)
            return time.perf_counter() - t, report


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("folder", help="folder of .obj/.off/.ply meshes")
    ap.add_argument("-o", "--out", help="output folder for the region files (default: a temp dir)")
    ap.add_argument("--cache", help="cache folder (default: <out>/.cache, as coseg segment)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--eigenpairs", type=int, default=coseg.DEFAULTS["eigenpairs"])
    ap.add_argument("--regions", type=int, default=coseg.DEFAULTS["regions"])
    ap.add_argument("--bench", type=int, metavar="N", default=0,
                    help="instead: time the per-shape stage N times with 1 and 2 workers, alternating")
    args = ap.parse_args()
    options = dict(eigenpairs=args.eigenpairs)

    if args.bench:
        times = {1: [], 2: []}
        for rep in range(args.bench):
            for workers in (1, 2) if rep % 2 == 0 else (2, 1):
                cache = tempfile.mkdtemp(prefix="coseg-bench-")
                try:
                    seconds, report = precompute_on(args.folder, workers, cache, options)
                    assert report.ok and report.cached == [], report
                finally:
                    shutil.rmtree(cache)
                times[workers].append(seconds)
                print(f"run {rep}: {workers} worker(s): {seconds:.2f} s for {len(report.computed)} shapes", flush=True)
        med = {w: statistics.median(t) for w, t in times.items()}
        best = {w: min(t) for w, t in times.items()}
        ratios = [a / b for a, b in zip(times[1], times[2])]
        print(f"median of {args.bench}: 1 worker {med[1]:.2f} s, 2 workers {med[2]:.2f} s, "
              f"speed-up {med[1] / med[2]:.2f}x (best {best[1]:.2f} / {best[2]:.2f} s = "
              f"{best[1] / best[2]:.2f}x; run by run {', '.join(f'{r:.2f}x' for r in ratios)}); "
              f"load average {os.getloadavg()}")
        return

    out = args.out or tempfile.mkdtemp(prefix="coseg-out-")
    cache = args.cache or os.path.join(out, ".cache")
    seconds, report = precompute_on(args.folder, args.workers, cache, options)
    print(f"per-shape stage on {args.workers} workers: {len(report.computed)} computed, "
          f"{len(report.cached)} already cached, {len(report.failed)} failed, {seconds:.2f} s")
    for path, message in report.failed:
        print(f"  failed: {message}")
    result = coseg.segment(args.folder, cache_dir=cache, out=out, regions=args.regions, **options)
    hits = result["outcomes"].count("hit")
    print(f"segment: {len(result['names'])} shapes, {hits} read warm from the cache, "
          f"{len(result['summary']['regions'])} regions -> {out}")


if __name__ == "__main__":
    main()
