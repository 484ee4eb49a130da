"""Studies — a TOML file run through every stage, on top of the library.

The machinery that runs any study sits at the top of this package; each study kind is a subpackage. Module map,
one entry per module (the details are in each module's own docstring):

- :mod:`~bladecase.study.schema` — the typed sections of a study file, validated with clear errors (:data:`SCHEMA`,
  :func:`load_study`);
- :mod:`~bladecase.study.keys` — :class:`Key`, :class:`StudyError`, a value checked against its key;
- :mod:`~bladecase.study.values` — value ranges and caps (``RANGES``, ``LIMITS``) and the value checks;
- :mod:`~bladecase.study.sections` — the ``[forcing]``, ``[execution]`` and other sections beyond the pipeline's
  own;
- :mod:`~bladecase.study.cross_checks` — the checks across keys and sections;
- :mod:`~bladecase.study.geometry_section` — ``[geometry]``, its kinds and the geometry it builds (a new
  parametric kind goes there);
- :mod:`~bladecase.study.study_file` — a study file read safely (regular file, capped size, UTF-8);
- :mod:`~bladecase.study.demo` — the embedded demo study (``bladecase demo``);
- :mod:`~bladecase.study.stages` — one plain function per stage (mesh, model, contact, reduced model, search);
- :mod:`~bladecase.study.choose` — which orbits to animate, and their frames;
- :mod:`~bladecase.study.render` — each chosen orbit checked and handed to the output writers;
- :mod:`~bladecase.study.reference` — the check of an orbit in a richer reference model;
- :mod:`~bladecase.study.validity` — the small-displacement limit: arcs cut where the tip amplitude exceeds
  ``[search] amplitude_limit`` × the span;
- :mod:`~bladecase.study.stress_limit` — the elastic limit: arcs, the every-node family and the Campbell bands cut
  where an orbit's peak von Mises stress exceeds ``[material] yield_strength``;
- :mod:`~bladecase.study.arc_figures` — an arc's figures read on its backbone, below the first internal-resonance
  tongue;
- :mod:`~bladecase.study.documents` — the modes file and the summary's parts (JSON);
- :mod:`~bladecase.study.publish` — staging and all-or-nothing publishing, the output folder's lock, a
  publication journal that a killed run's successor finishes;
- :mod:`~bladecase.study.manifest` — the proof of what a run wrote: content hashes of the published entries
  signed with the user's key; nothing else in an output folder is ever replaced or removed;
- :mod:`~bladecase.study.executor` — where independent tasks run: :class:`SerialExecutor`,
  :class:`ProcessExecutor`, :class:`DaskExecutor`, each with ``map(fn, items, *, shared=, desc=, progress=)``,
  chosen by :func:`make_executor`; tasks are module-level functions and carry light records (orbits pickle
  without their system; big shared arguments go once per worker);
- :mod:`~bladecase.study.tasks` — what every executor shares: the workers' environment, a task with its log
  transcript and wall time, the failing item named, one log line per finished item;
- :mod:`~bladecase.study.dask_executor` — the Dask cluster: addresses checked, connection and handshake under a
  time-out, cluster failures in words;
- :mod:`~bladecase.study.run` — :func:`run`, the whole chain;
- :mod:`~bladecase.study.pipeline` — the former one-module run's names, re-exported.

One subpackage per study kind, its stage and keys (its report and figures in the :mod:`bladecase.post`
subpackage of the same name; where the subpackage took the name of a former module, its ``__init__`` re-exports
that module's names): :mod:`~bladecase.study.rotation`, :mod:`~bladecase.study.rub`,
:mod:`~bladecase.study.nodal`, :mod:`~bladecase.study.disk`, :mod:`~bladecase.study.comparison`,
:mod:`~bladecase.study.forcing`, :mod:`~bladecase.study.convergence`, :mod:`~bladecase.study.casing`. A new kind:
its stage in ``<kind>/stage.py``, its keys in ``<kind>/keys.py`` (read by the schema, the sections or the cross
checks), its call in :mod:`~bladecase.study.run`; its words and figures called from
:mod:`bladecase.post.report`.

The command line (:mod:`bladecase.cli`) is a thin layer over this package.
"""

import importlib
import sys
import types
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # what a type checker and an IDE see; at run time each name is imported on first use
    from .dask_executor import DaskExecutor
    from .demo import demo_study
    from .executor import Executor, ProcessExecutor, SerialExecutor, keyword_task, make_executor
    from .run import RunResult, run
    from .schema import Study, StudyError, load_study

#: Where each public name lives: it is imported from there on first use, so that a module of this package (a
#: stage, the schema, a task a spawned worker unpickles) does not import the whole chain and its figures with it.
_WHERE = {"DaskExecutor": "dask_executor", "demo_study": "demo", "Executor": "executor",
          "ProcessExecutor": "executor", "SerialExecutor": "executor", "keyword_task": "executor",
          "make_executor": "executor", "RunResult": "run", "run": "run", "Study": "schema", "StudyError": "schema",
          "load_study": "schema"}


def __getattr__(name: str):
    """Import a public name the first time it is used (PEP 562)."""
    if name not in _WHERE:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{_WHERE[name]}", __name__), name)
    globals()[name] = value
    return value


class _Package(types.ModuleType):
    """This package, whose ``run`` stays the function :func:`run.run` once the module of that name is imported
    (the import system sets a package's attribute to each submodule it loads)."""

    def __setattr__(self, name: str, value) -> None:
        if name == "run" and isinstance(value, types.ModuleType):
            return
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package

__all__ = ["DaskExecutor", "Executor", "ProcessExecutor", "RunResult", "SerialExecutor", "Study", "StudyError",
           "demo_study", "keyword_task", "load_study", "make_executor", "run"]
