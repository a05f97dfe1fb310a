"""Studies in Python: many cases of one scene, on any ``concurrent.futures.Executor``."""

import json

from . import _ssn
from ._errors import SceneError


def run_case(scene, index, values, run="solve"):
    """Runs case ``index`` (the scene keys ``values``) as ``run`` in this process and returns
    its record: ``{"case", "values", "converged", "result"}`` (``result``: the ``to_dict()``
    of the run), or ``"error"`` instead of ``"result"`` when it could not run.

    The linear algebra is capped to the calling thread and stays capped: this is the task a
    study sends to its worker processes, where several workers share the cores.
    """
    _ssn.limit_threads(1)
    return json.loads(_ssn.run_case(scene, index, dict(values), run))


def run_cases(scene, numbered, run="solve"):
    """``run_case`` of each ``(index, values)`` of ``numbered``, in order: one task of a study
    sent in batches (``study(..., batch=n)``)."""
    return [run_case(scene, index, values, run) for index, values in numbered]


class StudyRecords(list):
    """The records of a study, one per case in case order, with its table."""

    def __init__(self, records, run, keys):
        super().__init__(records)
        self.run = run
        self.keys = list(keys)

    def _json(self):
        return json.dumps(list(self))

    def columns(self):
        """The table of ``ssn study`` as ``[(column, [cells])]``."""
        return _ssn.study_table(self.run, self.keys, self._json())

    def table(self):
        """The table of ``ssn study`` (one row per case: ``case``, the varied keys, a list
        value spread over ``key[i]`` columns, ``converged``, ``termination``, ``error``,
        the quantities of the run kind): a pandas DataFrame when pandas is installed, else
        a dict of lists."""
        columns = self.columns()
        try:
            import pandas
        except ImportError:
            return {name: cells for name, cells in columns}
        return pandas.DataFrame({name: cells for name, cells in columns})

    def to_csv(self, path):
        """Writes the table as the ``results.csv`` of ``ssn study``."""
        with open(path, "w", encoding="utf-8") as f:
            f.write(_ssn.study_csv(self.run, self.keys, self._json()))


def study(scene, cases, executor=None, run="solve", batch=1):
    """Runs ``scene`` with each case's values (a list of ``{key: value}`` dicts, the keys of
    ``Scene.with_values``) as ``run`` (``"solve"``, ``"sweep"``, ``"solutions"``).

    ``executor``: any ``concurrent.futures.Executor`` (a process pool, Dask's
    ``Client.get_executor()``, dask-jobqueue, mpi4py's ``MPIPoolExecutor``); ``None`` runs
    the cases here, one after the other. ``batch``: cases per task sent to the executor
    (more than 1 spreads an executor's cost per task, which matters for cases of a few
    milliseconds; see docs/studies.md). Every case is checked before any runs (a bad one
    raises ``SceneError`` naming it). Returns the records in case order
    (``StudyRecords``: a list with ``table()``).
    """
    cases = [dict(c) for c in cases]
    if isinstance(batch, bool) or not isinstance(batch, int) or batch < 1:
        raise SceneError(f"invalid batch {batch!r}: allowed an integer >= 1")
    if run not in ("solve", "sweep", "solutions"):
        raise SceneError(f'invalid run {run!r}: allowed "solve", "sweep" or "solutions"')
    for index, values in enumerate(cases):
        try:
            scene.with_values(values)
        except SceneError as e:
            raise SceneError(f"case {index} ({values}): {e}") from None
    keys = []
    for values in cases:
        keys.extend(k for k in values if k not in keys)
    if executor is None:
        previous = _ssn.limit_threads(1)
        try:
            records = [
                json.loads(_ssn.run_case(scene, i, v, run)) for i, v in enumerate(cases)
            ]
        finally:
            _ssn.limit_threads(previous)
    else:
        numbered = list(enumerate(cases))
        futures = [
            executor.submit(run_cases, scene, numbered[start : start + batch], run)
            for start in range(0, len(numbered), batch)
        ]
        records = [record for f in futures for record in f.result()]
    return StudyRecords(records, run, keys)


def study_file(scene, path):
    """The run kind and the cases of a study file of ``ssn study`` (checked against
    ``scene``): ``(run, [{key: value}])``, for ``study(scene, cases, run=run)``."""
    run, _keys, cases = _ssn.study_cases(scene, path)
    return run, cases
