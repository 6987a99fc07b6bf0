#!/usr/bin/env python3
"""Map softrne.fit over many data sets with Dask (dask.distributed): one fit per task.

A sweep that outgrows one machine (many data sets, many robots, many seeds) is a map of
independent fits. Each task here gets a Robot (it pickles as its description) and the path of
a data set, and returns the fit report (a dict, as `softrne-fit --report` writes it), so
nothing but small values travels. Without --scheduler the script starts a LocalCluster on
this machine; with --scheduler tcp://HOST:8786 the same code runs on a real cluster
(`dask scheduler` on one machine, `dask worker tcp://HOST:8786` on the others), where every
worker needs softrne installed (pip install .) and the data set paths readable (a shared file
system, or copy them first). Dask is the scheduler; this script writes none.

    pip install "dask[distributed]"
    python3 examples/python/fit_many_dask.py                 # the bundled arm's data in 6 pieces
    python3 examples/python/fit_many_dask.py --scheduler tcp://HOST:8786 --data a.csv b.csv ...
"""

from __future__ import annotations

import argparse
import pathlib
import tempfile

import softrne

ARM = pathlib.Path(__file__).resolve().parents[1] / "data" / "arm-a-1"


def fit_one(robot: softrne.Robot, data_path: str, seed: int = 1) -> dict:
    """One task: the fit of `robot` to one data set (threads=1: the cluster gives the parallelism)."""
    report = softrne.fit(robot, data_path, seed=seed, threads=1)
    return {"data": data_path, "report": report}


def split_bundled_data(robot: softrne.Robot, directory: pathlib.Path, pieces: int = 3) -> list[str]:
    """The bundled arm's train and test runs cut into `pieces` each, as data set files."""
    paths = []
    for name in ("train", "test"):
        d = softrne.read_dataset(ARM / f"{name}.csv", robot, require_angles=True)
        n = len(d) // pieces
        for k in range(pieces):
            rows = slice(k * n, (k + 1) * n)
            path = directory / f"{name}-{k}.csv"
            softrne.write_dataset(path, robot, d.t[rows], d.pressures[rows], d.angles[rows])
            paths.append(str(path))
    return paths


def fit_all(client, robot: softrne.Robot, paths: list[str]) -> list[dict]:
    """Maps fit_one over the data sets on the cluster behind `client`; results in order."""
    robot_on_cluster = client.scatter(robot, broadcast=True)  # sent once, not once per task
    futures = client.map(fit_one, [robot_on_cluster] * len(paths), paths, pure=False)
    return client.gather(futures)


def main() -> None:
    from dask.distributed import Client, LocalCluster

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--robot", default=str(ARM / "robot.json"))
    ap.add_argument("--data", nargs="*", help="data set CSVs with measured angles (default: the bundled arm's, in pieces)")
    ap.add_argument("--scheduler", help="address of a running Dask scheduler (default: a LocalCluster here)")
    ap.add_argument("--workers", type=int, default=2, help="LocalCluster worker processes")
    args = ap.parse_args()

    robot = softrne.Robot.from_json(args.robot)
    with tempfile.TemporaryDirectory() as tmp:
        paths = args.data or split_bundled_data(robot, pathlib.Path(tmp))
        if args.scheduler:
            client = Client(args.scheduler)
        else:
            client = Client(LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True))
        with client:
            results = fit_all(client, robot, paths)
    for r in results:
        rep = r["report"]
        k = {p["name"]: p["value"] for p in rep["parameters"]}
        print(f"{pathlib.Path(r['data']).name:>12}: median error {rep['train']['before']['median']:.4f} -> "
              f"{rep['train']['after']['median']:.4f} rad, stiffness.u1 {k['stiffness.u1']:.2f}, "
              f"{rep['simulations']} simulations")


if __name__ == "__main__":
    main()
