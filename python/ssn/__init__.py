"""Periodic vibrations of structures with unilateral contact, from Python.

The Python face of ``semismooth-contact`` and of the ``ssn`` program: the same scenes
(keys, defaults and errors), the same runs and the same JSON documents.

>>> import ssn
>>> scene = ssn.Scene.from_file("scenes/paper_fig1.toml")          # doctest: +SKIP
>>> solution = ssn.solve(scene.with_values({"contact.gap": 0.3}))   # doctest: +SKIP
>>> solution.converged, solution.displacement.min()                 # doctest: +SKIP

- ``Scene.from_file``, ``Scene.from_toml``, ``Scene.rod``, ``Scene.from_matrices``;
  ``scene.with_values({...})`` (the keys of ``ssn solve --set``);
- ``solve``, ``sweep``, ``solutions``, ``stability``: results with numpy arrays and
  ``to_dict()`` equal to the JSON of ``ssn solve/sweep/solutions --json``; the GIL is
  released while they run;
- ``Model.from_scene(scene)``: the structure, ``frequencies(count)`` and
  ``reduce(method, modes=None, cutoff=None)`` (Craig-Bampton or massless boundary);
- ``modes(scene)``: the backbone of the scene's ``[modes]``, the dict of ``ssn modes --json``;
- ``study(scene, cases, executor=None, run="solve")`` on any
  ``concurrent.futures.Executor``; ``study_file`` reads the cases of an ``ssn study`` file;
- ``Solution.termination_kind``: why the solve stopped, a ``Termination`` member;
- exceptions by kind, all ``SsnError``: ``SceneError`` (a ``ValueError``): a bad scene,
  value or case, with the command line's message (file, key, value, what is allowed);
  ``SceneTypeError`` (a ``SceneError`` and a ``TypeError``): a value of the wrong type;
  ``TooLargeError`` (a ``SceneError``): a run refused up front by its memory or work
  estimate; ``SolveError`` (a ``RuntimeError``): the computation could not be carried out,
  ``NotConvergedError`` (``termination``, ``iterations``, ``residual_norm``) among them.
"""

from ._ssn import (
    FrequencyResponse,
    Model,
    Scene,
    Solution,
    SolutionSet,
    Stability,
    limit_threads,
    modes,
    solutions,
    solve,
    stability,
    sweep,
)
from ._errors import (
    NotConvergedError,
    SceneError,
    SceneTypeError,
    SolveError,
    SsnError,
    TooLargeError,
)
from ._termination import Termination
from ._study import StudyRecords, run_case, study, study_file

__all__ = [
    "FrequencyResponse",
    "Model",
    "NotConvergedError",
    "Scene",
    "SceneError",
    "SceneTypeError",
    "Solution",
    "SolutionSet",
    "SolveError",
    "SsnError",
    "Stability",
    "StudyRecords",
    "Termination",
    "TooLargeError",
    "limit_threads",
    "modes",
    "run_case",
    "solutions",
    "solve",
    "stability",
    "study",
    "study_file",
    "sweep",
]
