"""Studies — a TOML file run through every stage, on top of the library.

- :mod:`~bladecase.study.schema` — the typed sections of a study file, validated with clear errors;
- :mod:`~bladecase.study.demo` — the embedded demo study (``bladecase demo``);
- :mod:`~bladecase.study.stages` — one plain function per stage (mesh, model, contact, reduced model, search);
- :mod:`~bladecase.study.choose` — which orbits to animate, and their frames;
- :mod:`~bladecase.study.render` — each chosen orbit checked and handed to the output writers;
- :mod:`~bladecase.study.documents` — the modes file and the summary's parts (JSON);
- :mod:`~bladecase.study.publish` — staging and all-or-nothing publishing;
- :mod:`~bladecase.study.executor` — where independent tasks run (serial, local processes, Dask);
- :mod:`~bladecase.study.run` — :func:`run`, the whole chain;
- one subpackage per study kind, its stage and keys (its report and figures in the :mod:`bladecase.post`
  subpackage of the same name): :mod:`~bladecase.study.rotation`, :mod:`~bladecase.study.rub`,
  :mod:`~bladecase.study.nodal`, :mod:`~bladecase.study.disk`, :mod:`~bladecase.study.comparison`,
  :mod:`~bladecase.study.forcing`, :mod:`~bladecase.study.convergence`, :mod:`~bladecase.study.casing`.

The command line (:mod:`bladecase.cli`) is a thin layer over this package.
"""

from .dask_executor import DaskExecutor
from .demo import demo_study
from .executor import Executor, ProcessExecutor, SerialExecutor, keyword_task, make_executor
from .run import RunResult, run
from .schema import Study, StudyError, load_study

__all__ = ["DaskExecutor", "Executor", "ProcessExecutor", "RunResult", "SerialExecutor", "Study", "StudyError",
           "demo_study", "keyword_task", "load_study", "make_executor", "run"]
