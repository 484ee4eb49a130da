"""The Dask executor of :mod:`bladecase.study.executor`: tasks on a ``dask.distributed`` cluster — a
``LocalCluster`` it starts and closes, or an existing scheduler by address or ``Client`` — with the address
checked before any connection (scheme, host and port, the transport installed), the whole connection and
Dask's handshake under the executor's time-out, and every failure of the cluster (refused, unknown host, a
service that is not a scheduler, no worker, a worker that died, a lost connection) in one clear message.
"""

from __future__ import annotations

import uuid
from collections.abc import Callable, Iterable
from typing import Any

from ..progress import progress_counter
from .tasks import WORKER_ENV, A, ItemLog, Logged, R, check_workers, environ_kept, label, named, relay

__all__ = ["HOST_PORT_SCHEMES", "DaskExecutor"]


class DaskExecutor:
    """Tasks on a ``dask.distributed`` cluster.

    ``scheduler=None``: a ``LocalCluster`` of ``workers`` processes (default: one per core), one thread
    each, started at the first ``map`` and closed by :meth:`close` (or at the end of a ``with`` block);
    ``cluster_options`` go to ``LocalCluster`` (e.g. ``dashboard_address=":8787"``, ``memory_limit``).
    ``scheduler="tcp://host:8786"`` (or a cluster object such as a
    dask-jobqueue ``SLURMCluster``, or a ``distributed.Client``): an existing cluster, connected to at the
    first ``map`` within ``timeout`` seconds (the connection and Dask's handshake; ``ValueError`` naming the
    address when that fails: not an address, a transport not installed, nothing listening, no answer in
    time), and its workers' bladecase version checked (RuntimeError when one differs: workers need bladecase
    installed at the same version; also when it has no worker within ``timeout``); :meth:`close` closes only
    the connection this executor opened, never a cluster it did not start.

    ``fn`` and the items are pickled with cloudpickle; ``shared`` is scattered to every worker once per
    ``map``.  Progress advances as tasks complete on any worker.

    >>> DaskExecutor(workers=2)
    DaskExecutor(local cluster, workers=2)
    >>> DaskExecutor("tcp://scheduler:8786")
    DaskExecutor('tcp://scheduler:8786')
    """

    name = "dask"

    def __init__(self, scheduler: Any = None, workers: int | None = None, *, timeout: float = 30.0,
                 **cluster_options: Any):
        self.workers = check_workers(workers, "DaskExecutor")
        if scheduler is not None:
            if workers is not None or cluster_options:
                raise ValueError(f"DaskExecutor: workers and cluster options apply to a local cluster only, not to "
                                 f"the existing scheduler {scheduler!r}; valid: scheduler=None, or no workers")
            scheduler = _check_scheduler(scheduler)
        if isinstance(timeout, bool) or not isinstance(timeout, (int, float)) or not 0 < timeout < float("inf"):
            raise ValueError(f"DaskExecutor: timeout must be > 0 seconds (a finite number), got {timeout!r}")
        self.scheduler = scheduler
        self.timeout = float(timeout)
        self.cluster_options = cluster_options
        self._client = None
        self._cluster = None
        self._own_client = False

    @property
    def client(self):
        """The ``distributed.Client`` (the local cluster is started, or the scheduler connected, on first use).

        An existing scheduler is connected to within :attr:`timeout` seconds, the Dask handshake included;
        every failure to reach it is a ``ValueError`` naming the address (not a Dask address, a transport that
        is not installed, nothing listening there, no answer within the time-out), and a scheduler without
        workers (none joining within the time-out) a ``RuntimeError``."""
        if self._client is None:
            from distributed import Client, LocalCluster

            if self.scheduler is None:
                self._start_local(LocalCluster)
                self._client, self._own_client = Client(self._cluster), True
            elif isinstance(self.scheduler, Client):
                self._client = self.scheduler
            else:
                self._client = _connect(self.scheduler, self.timeout)
                self._own_client = True
            if self._cluster is None:
                self._wait_for_workers()
                self._check_versions()
        return self._client

    def _start_local(self, LocalCluster) -> None:
        """The local cluster (``ValueError`` for a cluster option it does not take, ``RuntimeError`` if it fails)."""
        options = dict(dashboard_address=None, env=dict(WORKER_ENV)) | self.cluster_options
        what = f"a local Dask cluster of {self.workers or 'one per core'} worker(s)"
        try:
            with environ_kept():  # Dask's nannies write their pre-spawn variables into os.environ
                self._cluster = LocalCluster(n_workers=self.workers, threads_per_worker=1, processes=True, **options)
        except (TypeError, OSError, TimeoutError, RuntimeError) as exc:  # a port in use, workers that do not start
            option = _unexpected_keyword(exc)
            if option is not None:  # a cluster option neither LocalCluster nor its workers take
                raise ValueError(f"DaskExecutor: cannot start {what} with the options {self.cluster_options!r}: "
                                 f"{option}; valid: keyword arguments of distributed.LocalCluster (and of its "
                                 "workers)") from None
            raise RuntimeError(f"DaskExecutor: cannot start {what} ({type(exc).__name__}: {exc})") from None

    def _wait_for_workers(self) -> None:
        """An existing cluster has a worker, or one joins within the time-out (else close and raise RuntimeError)."""
        try:
            if self._client.nthreads():
                return
            self._client.wait_for_workers(1, timeout=self.timeout)
        except (OSError, TimeoutError) as exc:  # OSError: Dask's CommClosedError
            self.close()
            raise RuntimeError(f"the Dask scheduler {_where(self.scheduler)} has no worker (none joined within "
                               f"{self.timeout:g} s, the executor's timeout): start workers on it (`dask worker "
                               f"ADDRESS`), or run without a scheduler ({type(exc).__name__}: {exc})") from None

    def _check_versions(self) -> None:
        """Every worker of an existing cluster runs this bladecase version (else close and raise RuntimeError)."""
        from .. import __version__

        try:
            found = self._client.run(_bladecase_version)
            problem = ", ".join(f"{w} has {v}" for w, v in sorted(found.items()) if v != __version__)
        except Exception as exc:  # bladecase missing on a worker: it cannot unpickle the probe
            problem = f"a worker cannot import bladecase ({type(exc).__name__}: {exc})"
        if problem:
            self.close()
            raise RuntimeError(f"Dask workers of {self.scheduler!r} must run bladecase {__version__} (install it "
                               f"there at the same version): {problem}")

    def map(self, fn: Callable[..., R], items: Iterable[A], *, shared: dict[str, Any] | None = None,
            desc: str = "tasks", progress: bool = False) -> list[R]:
        from distributed import as_completed

        items = list(items)
        if not items:
            return []
        from distributed import KilledWorker
        from distributed.client import FutureCancelledError

        client = self.client
        futures: list = []
        kwargs: dict = {}
        results: list[Any] = [None] * len(items)
        try:
            try:
                kwargs = {k: client.scatter([v], broadcast=True, hash=False)[0] for k, v in (shared or {}).items()}
                task, tag = Logged(fn), uuid.uuid4().hex[:8]
                futures = [client.submit(task, x, kwargs, key=f"bladecase-{tag}-{i}", pure=False)
                           for i, x in enumerate(items)]
                workers = len(client.nthreads())
            except (OSError, TimeoutError) as exc:  # the connection lost (CommClosedError is an OSError)
                raise self._lost(exc) from None
            index = {f.key: i for i, f in enumerate(futures)}
            done = ItemLog(desc, len(items))
            with progress_counter(len(items), desc, enabled=progress and len(items) > 1, unit="task") as bar:
                bar.set_postfix_str(f"{workers} workers")
                for fut in as_completed(futures):
                    i = index[fut.key]
                    try:
                        results[i], lines, seconds = fut.result()
                    except (KilledWorker, FutureCancelledError) as exc:  # not the task's own error: Dask's
                        raise RuntimeError(f"{desc or 'task'} {i} (item {label(items[i])}) did not run on the Dask "
                                           f"cluster {_where(self.scheduler)}: {_dask_failure(exc)}") from None
                    except Exception as exc:
                        raise named(exc, desc, i, items[i]) from None
                    relay(lines)
                    done(items[i], seconds)
                    bar.update()
        finally:
            try:
                client.cancel([f for f in futures if not f.done()])
            except (OSError, TimeoutError):  # the connection is gone: nothing left to cancel
                pass
            del futures, kwargs  # release the scattered data and the results on the workers
        return results

    def _lost(self, exc: BaseException) -> RuntimeError:
        return RuntimeError(f"lost the connection to the Dask scheduler {_where(self.scheduler)} "
                            f"({type(exc).__name__}: {exc}); is it still running?")

    def close(self) -> None:
        """Close the connection this executor opened and the local cluster it started (if any)."""
        try:
            if self._client is not None and self._own_client:
                self._client.close()
            if self._cluster is not None:
                self._cluster.close()
        except (OSError, TimeoutError):  # the connection already lost: nothing more to release
            pass
        finally:
            self._client = self._cluster = None
            self._own_client = False

    def __enter__(self) -> DaskExecutor:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __repr__(self) -> str:
        if self.scheduler is None:
            return f"DaskExecutor(local cluster, workers={self.workers})"
        return f"DaskExecutor({self.scheduler!r})"


def _bladecase_version() -> str:
    """The bladecase version of the process this runs in (a Dask worker)."""
    from .. import __version__

    return __version__


#: Address schemes of Dask's transports whose addresses are ``host:port``.
HOST_PORT_SCHEMES = ("tcp", "tls", "ws", "wss", "ucx")

#: What to write instead of an address that is not understood.
_ADDRESS_HELP = "valid: a Dask scheduler address such as 'tcp://host:8786', a distributed.Client or a cluster object"


def _unexpected_keyword(exc: BaseException | None) -> str | None:
    """The ``TypeError`` message of an unexpected keyword argument in ``exc`` or what caused it, if any."""
    seen = 0
    while exc is not None and seen < 20:
        if isinstance(exc, TypeError) and "keyword argument" in str(exc):
            return str(exc)
        exc, seen = exc.__cause__ or exc.__context__, seen + 1
    return None


def _where(scheduler: Any) -> str:
    if scheduler is None:
        return "(a local cluster)"
    return repr(scheduler) if isinstance(scheduler, str) else type(scheduler).__name__


def _check_scheduler(scheduler: Any) -> Any:
    """An existing scheduler as given (a ``Client`` or a cluster object), or its address checked and stripped.

    An address is ``[scheme://]host:port`` (no scheme: ``tcp``) with a port in 1..65535, of a transport Dask
    knows and has installed (``ucx`` needs ``distributed-ucxx``); ``inproc://`` addresses (one process) pass as
    they are.  ``ValueError`` naming the address and what is valid otherwise.  Nothing is connected to here."""
    if isinstance(scheduler, str):
        address = scheduler.strip()
        if not address:
            raise ValueError(f"DaskExecutor: scheduler address is empty; {_ADDRESS_HELP}, or None (a local cluster)")
        scheme, sep, loc = address.partition("://")
        if not sep:
            scheme, loc = "tcp", address
        scheme = scheme.lower()
        where = f"Dask scheduler {scheduler!r}"
        if scheme == "inproc":
            _transport(scheme, where)
            return address
        if scheme not in HOST_PORT_SCHEMES:
            raise ValueError(f"{where}: unknown address scheme {scheme!r}; valid: "
                             f"{', '.join(s + '://host:port' for s in HOST_PORT_SCHEMES)} (e.g. 'tcp://host:8786')")
        _host_port(loc, where)
        _transport(scheme, where)
        return f"{scheme}://{loc}"
    if isinstance(scheduler, (bool, int, float, bytes, list, tuple, dict, set)) or not (
            _is_client(scheduler) or hasattr(scheduler, "scheduler_address")):
        raise ValueError(f"DaskExecutor: scheduler must be an address string, got {type(scheduler).__name__} "
                         f"{scheduler!r}; {_ADDRESS_HELP}")
    return scheduler


def _is_client(obj: Any) -> bool:
    try:
        from distributed import Client
    except ImportError:
        return False
    return isinstance(obj, Client)


def _host_port(loc: str, where: str) -> tuple[str, int]:
    """``(host, port)`` of ``host:port`` (``[v6 address]:port``); ``ValueError`` naming ``where`` otherwise."""
    host, sep, port = loc.rpartition(":")
    if host.startswith("[") and host.endswith("]"):
        host = host[1:-1]
    bad = (not sep or not host or any(c in host for c in "/[] ") or not port.isdigit()
           or not 1 <= int(port) <= 65535 or (":" in host and not loc.startswith("[")))
    if bad:
        raise ValueError(f"{where}: expected host:port after the scheme, with a port in 1..65535 (an IPv6 "
                         f"host in brackets, [::1]:8786), got {loc!r}; e.g. 'tcp://host:8786'")
    return host, int(port)


def _transport(scheme: str, where: str) -> None:
    """Dask has the transport of ``scheme`` installed (``ValueError`` naming ``where`` otherwise)."""
    try:
        from distributed.comm import registry
    except ImportError:
        raise ValueError(f"{where}: dask.distributed is not installed (pip install 'dask[distributed]')") from None
    try:
        registry.get_backend(scheme).get_connector()
    except (TypeError, ImportError, ValueError, AttributeError) as exc:  # UCX: an abstract connector without ucxx
        if scheme == "ucx":
            raise ValueError(f"{where}: the UCX transport is not installed (pip install distributed-ucxx) — use "
                             "tcp://host:port") from None
        raise ValueError(f"{where}: Dask's {scheme!r} transport is not available here ({type(exc).__name__}: "
                         f"{exc}) — use tcp://host:port") from None


def _reachable(address: str, timeout: float) -> None:
    """Something listens at a ``host:port`` address (``ValueError`` naming it otherwise): a refused connection
    fails at once, not after the time-out Dask's own connect retries for."""
    import socket

    scheme, _, loc = address.partition("://")
    if scheme not in HOST_PORT_SCHEMES or scheme == "ucx":
        return
    where = f"Dask scheduler {address!r}"
    host, port = _host_port(loc, where)
    try:
        with socket.create_connection((host, port), timeout=timeout):
            pass
    except socket.gaierror as exc:
        raise ValueError(f"{where}: host {host!r} is not known ({exc.strerror or exc}); check the address") from None
    except ConnectionRefusedError:
        raise ValueError(f"{where}: connection refused: no Dask scheduler listens on port {port} of {host} (start "
                         "one with `dask scheduler`, or check host and port)") from None
    except TimeoutError:
        raise ValueError(f"{where}: no answer to the connection within {timeout:g} s (the executor's timeout): "
                         "host unreachable or a firewall drops the connection; check the address") from None
    except OSError as exc:
        raise ValueError(f"{where}: cannot connect ({exc.strerror or exc}); check the address") from None


def _connect(scheduler: Any, timeout: float):
    """A ``distributed.Client`` of the scheduler at ``scheduler`` (an address or a cluster object), connected
    (handshake included) within ``timeout`` seconds: ``ValueError`` naming the address otherwise."""
    from distributed import Client

    address = scheduler if isinstance(scheduler, str) else getattr(scheduler, "scheduler_address", None)
    if isinstance(address, str):
        _reachable(address, timeout)

    class _Bounded(Client):
        """A Client whose start (connection and handshake) is cut off at ``timeout`` (Dask's own ``timeout``
        bounds the connection only: a peer that accepts and never answers holds it for ever)."""

        def start(self, **kwargs):
            try:
                super().start(callback_timeout=timeout, **kwargs)
            except BaseException:
                try:
                    self.close(timeout=min(timeout, 5.0))
                except Exception:
                    pass
                raise

    where = f"Dask scheduler {address if isinstance(address, str) else _where(scheduler)!r}"
    try:
        return _Bounded(scheduler, timeout=timeout)
    except TimeoutError as exc:  # asyncio's too (the same class since Python 3.11)
        raise ValueError(f"{where}: accepted the connection but did not complete Dask's handshake within "
                         f"{timeout:g} s (the executor's timeout): is a Dask scheduler (not a worker, not another "
                         f"service) listening there? ({type(exc).__name__}: {exc or 'timed out'})") from None
    except Exception as exc:  # CommClosedError (an OSError), a handshake Dask cannot read, a TLS setup, ...
        why = ("what it sent is not Dask's protocol" if isinstance(exc, MemoryError)  # a garbage frame length
               else f"{type(exc).__name__}: {exc}")
        raise ValueError(f"{where}: cannot connect to a Dask scheduler there ({why}); check the address (a "
                         "scheduler's, e.g. 'tcp://host:8786') and that it runs") from None


def _dask_failure(exc: BaseException) -> str:
    """Why Dask did not return a task's result (a worker died running it, the task was cancelled)."""
    from distributed import KilledWorker

    if isinstance(exc, KilledWorker):
        return (f"the workers running it died ({exc}): out of memory, or killed; give the workers more memory or "
                "run fewer tasks at once")
    return f"the task was cancelled ({exc}): the scheduler restarted or the connection to it was lost"
