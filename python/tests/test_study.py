"""Studies: on a real Dask cluster of worker processes, on a process pool and serially, the
same table; the table of the command line's ``ssn study`` for the same study file."""

import concurrent.futures
import subprocess

import pandas
import pytest

import ssn
from conftest import SCENES

FIG2 = SCENES / "paper_fig2.toml"
STUDY = """
run = "sweep"
[grid]
"contact.gap" = [0.25, 0.5, 0.75]
"forcing.amplitude" = [0.03, 0.04]
[random]
samples = 2
seed = 7
[random.keys."damping.zeta"]
distribution = "uniform"
low = 0.01
high = 0.02
"""


def cases():
    """12 sweeps: 3 gaps x 2 amplitudes x 2 random dampings."""
    return [
        {"contact.gap": g, "forcing.amplitude": a, "damping.zeta": z}
        for g in (0.25, 0.5, 0.75)
        for a in (0.03, 0.04)
        for z in (0.01, 0.015)
    ]


def test_a_study_on_a_dask_cluster_of_processes_gives_the_serial_table():
    distributed = pytest.importorskip("distributed")
    scene = ssn.Scene.from_file(FIG2)
    serial = ssn.study(scene, cases(), run="sweep")
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        # Worker processes, not threads of this one.
        pids = set(client.run(lambda: __import__("os").getpid()).values())
        assert len(pids) == 2 and __import__("os").getpid() not in pids
        on_dask = ssn.study(scene, cases(), executor=client.get_executor(), run="sweep")
    assert [r["case"] for r in on_dask] == list(range(12))
    assert all(r["converged"] for r in serial)
    pandas.testing.assert_frame_equal(on_dask.table(), serial.table())
    # The table has a row per case, the varied keys and the sweep's quantities.
    table = serial.table()
    assert len(table) == 12
    assert {"contact.gap", "forcing.amplitude", "damping.zeta", "peak_amplitude"} <= set(table)
    # The response grows with the load at a fixed gap and damping.
    for (gap, zeta), group in table.groupby(["contact.gap", "damping.zeta"]):
        peaks = group.sort_values("forcing.amplitude")["peak_amplitude"].to_numpy()
        assert peaks[1] > peaks[0], (gap, zeta)


def test_a_process_pool_gives_the_serial_records():
    scene = ssn.Scene.from_file(FIG2)
    few = cases()[:4]
    serial = ssn.study(scene, few, run="sweep")
    with concurrent.futures.ProcessPoolExecutor(max_workers=2) as pool:
        pooled = ssn.study(scene, few, executor=pool, run="sweep")
        batched = ssn.study(scene, few, executor=pool, run="sweep", batch=3)
    strip = lambda r: {**r, "result": {**r["result"], "solve_seconds": 0, "stability_seconds": 0}}
    assert [strip(r) for r in pooled] == [strip(r) for r in serial]
    # Two tasks, of three cases and of one: the records in case order all the same.
    assert [strip(r) for r in batched] == [strip(r) for r in serial]
    with pytest.raises(ssn.SceneError, match="batch"):
        ssn.study(scene, few, executor=pool, batch=0)


def test_the_study_table_of_python_equals_the_command_lines(ssn_bin, tmp_path):
    study_file = tmp_path / "study.toml"
    study_file.write_text(STUDY)
    out = tmp_path / "out"
    done = subprocess.run(
        [ssn_bin, "study", str(FIG2), str(study_file), "--out", str(out), "--quiet"],
        check=False,
    )
    scene = ssn.Scene.from_file(FIG2)
    run, study_cases = ssn.study_file(scene, study_file)
    assert run == "sweep" and len(study_cases) == 12
    records = ssn.study(scene, study_cases, run=run)
    # Exit code 0 when every case converged, 1 when some did not (the table all the same).
    assert done.returncode == (0 if all(r["converged"] for r in records) else 1)
    records.to_csv(tmp_path / "python.csv")
    assert (tmp_path / "python.csv").read_text() == (out / "results.csv").read_text()
    # The Parquet table holds the same cells (a missing value is null in both; pandas gives
    # it as NaN or None by column type).
    nulls_as_none = lambda frame: frame.astype(object).where(frame.notna(), None)
    parquet = pandas.read_parquet(out / "results.parquet")
    pandas.testing.assert_frame_equal(
        nulls_as_none(parquet), nulls_as_none(records.table()), check_dtype=False
    )


def test_a_bad_case_is_refused_before_any_case_runs():
    scene = ssn.Scene.from_file(FIG2)
    with pytest.raises(ssn.SceneError, match=r"case 1 .*contact\.gap"):
        ssn.study(scene, [{"contact.gap": 0.3}, {"contact.gap": "wide"}])
