"""What a study case costs from Python beyond its solve: many small solves of the canonical
rod (``scenes/paper_fig1.toml``, H = 20, seeded random ``omega / omega_1`` in [0.8, 1.2])
run serially in this process, on a process pool and on a Dask ``LocalCluster`` of worker
processes (1 and 2 workers), against the same solves as a plain loop of ``ssn.solve`` in
this process (the scene with the case's values, its structure, the solve: what a user
would write without ``ssn.study``), measured in the same run.

    python python/benchmarks/study_overhead.py [CASES] [--write]

(default 1000 cases; needs the package, ``distributed`` for the Dask rows). ``--write`` puts
the table into ``docs/studies.md`` (its ``python-overhead`` generated block).
"""

import concurrent.futures
import os
import pathlib
import platform
import random
import sys
import time

import ssn

ROOT = pathlib.Path(__file__).resolve().parents[2]
BLOCK = "python-overhead"
#: Cases per task in the batched Dask rows.
BATCH = 50


def machine_note():
    cpu = platform.processor() or platform.machine()
    try:
        for line in open("/proc/cpuinfo", encoding="utf-8"):
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    load = os.getloadavg()[0]
    return f"{cpu}, {os.cpu_count()} cores, load average {load:.2f}"


def measure(label, run, cases):
    started = time.perf_counter()
    records = run()
    seconds = time.perf_counter() - started
    assert [r["case"] for r in records] == list(range(len(cases))), label
    converged = sum(bool(r["converged"]) for r in records)
    return label, seconds, converged


def solve_loop(scene, cases):
    """Seconds of a plain loop of ``ssn.solve`` over the cases, on one thread as a study
    case runs, and how many converged."""
    previous = ssn._ssn.limit_threads(1)
    try:
        started = time.perf_counter()
        converged = sum(bool(ssn.solve(scene.with_values(c)).converged) for c in cases)
        return time.perf_counter() - started, converged
    finally:
        ssn._ssn.limit_threads(previous)


def main():
    args = sys.argv[1:]
    write = "--write" in args
    numbers = [a for a in args if a != "--write"]
    n = int(numbers[0]) if numbers else 1000
    rng = random.Random(2026)
    cases = [{"forcing.omega_ratio": rng.uniform(0.8, 1.2)} for _ in range(n)]
    scene = ssn.Scene.from_file(ROOT / "scenes" / "paper_fig1.toml")
    loop_seconds, loop_converged = solve_loop(scene, cases)
    rows = [measure("`ssn.study`, serial in this process", lambda: ssn.study(scene, cases), cases)]
    for workers in (1, 2):
        with concurrent.futures.ProcessPoolExecutor(max_workers=workers) as pool:
            ssn.study(scene, cases[:workers], executor=pool)  # start the workers
            rows.append(
                measure(
                    f"process pool, {workers} worker{'s' if workers > 1 else ''}",
                    lambda: ssn.study(scene, cases, executor=pool),
                    cases,
                )
            )
    try:
        import distributed
    except ImportError:
        distributed = None
    if distributed is not None:
        for workers in (1, 2):
            with distributed.LocalCluster(
                n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None
            ) as cluster, distributed.Client(cluster) as client:
                executor = client.get_executor()
                ssn.study(scene, cases[:workers], executor=executor)  # warm the workers
                for batch in (1, BATCH):
                    rows.append(
                        measure(
                            f"Dask LocalCluster, {workers} worker "
                            f"process{'es' if workers > 1 else ''}, batch = {batch}",
                            lambda: ssn.study(scene, cases, executor=executor, batch=batch),
                            cases,
                        )
                    )
    bare = loop_seconds / n
    page = (
        f"`python python/benchmarks/study_overhead.py --write` ({machine_note()})\n\n"
        f"{n} solves of the canonical rod (`scenes/paper_fig1.toml`, H = 20) at seeded random "
        f"omega/omega_1 in [0.8, 1.2]. The reference is a plain loop of "
        f"`ssn.solve(scene.with_values(case))` in this process, on one thread: "
        f"{1e3 * bare:.3f} ms per case ({loop_converged} converged).\n\n"
        "| run | converged | per case | cases per second | cost per case over the loop |\n"
        "| --- | --- | --- | --- | --- |\n"
    )
    for label, seconds, converged in rows:
        per_case = seconds / n
        # Per worker: a pool of w workers spends w x the wall time per case.
        workers = 2 if "2 worker" in label else 1
        over = workers * per_case - bare
        page += (
            f"| {label} | {converged} | {1e3 * per_case:.3f} ms | {1 / per_case:.0f} | "
            f"{1e3 * over:.3f} ms = {over / bare:.2f} x the loop |\n"
        )
    page += (
        "\nCost per case over the loop: the wall time per case times the workers, less the "
        "loop's time per case (the JSON record, pickling, the executor's scheduling; negative "
        "when the run is cheaper than the loop, which builds the Python result objects).\n"
    )
    print(page)
    if write:
        docs = ROOT / "docs" / "studies.md"
        text = docs.read_text(encoding="utf-8")
        start = f"<!-- docs_tables {BLOCK}: generated, do not edit -->"
        end = f"<!-- docs_tables {BLOCK}: end -->"
        head, rest = text.split(start, 1)
        _, tail = rest.split(end, 1)
        docs.write_text(f"{head}{start}\n\n{page.strip()}\n\n{end}{tail}", encoding="utf-8")
        print(f"wrote {docs}", file=sys.stderr)


if __name__ == "__main__":
    main()
