"""examples/python/fit_many_dask.py: fits mapped over data sets on a Dask LocalCluster equal
the same fits run here (where dask.distributed is installed)."""

from __future__ import annotations

import importlib.util
import json

import pytest

import softrne

from conftest import REPO


def load_example():
    spec = importlib.util.spec_from_file_location("fit_many_dask", REPO / "examples/python/fit_many_dask.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_fits_on_a_local_cluster(robot, tmp_path):
    distributed = pytest.importorskip("dask.distributed")
    ex = load_example()
    paths = ex.split_bundled_data(robot, tmp_path, pieces=5)
    assert len(paths) == 10
    paths = [paths[0], paths[-1]]  # two short data sets (2 and 2.8 s) keep the test short
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        results = ex.fit_all(client, robot, paths)
    assert [r["data"] for r in results] == paths

    def strip(rep):
        rep = json.loads(json.dumps(rep))
        rep.pop("wall_seconds")
        return rep

    for path, r in zip(paths, results):
        assert strip(r["report"]) == strip(softrne.fit(robot, path, threads=1))
