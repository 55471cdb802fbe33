"""Where runs run: local processes (a thread per running run, ``--jobs`` at once) or Ray tasks on a cluster.

Both call ``on_record(record)`` in the calling thread as each run ends, and end every run when the caller's
``KeyboardInterrupt`` arrives (the runs still going are not recorded; the interrupt is raised again after).

Ray: each run is a task (``num_cpus`` of its scenario, 1 by default) that runs :func:`run.run_once` on its node in
a folder of that node, then sends the folder back packed; it is unpacked into ``<out>/runs/<name>`` here. A
task whose worker or node dies is run once more, on another node where there is one (a small tracker actor
knows where each run started), and recorded once. Ctrl-C cancels every task (each ends its run's processes)
and then ends, on every node, any process still carrying the batch's marker.
"""
import concurrent.futures
import glob
import io
import os
import shutil
import socket
import tarfile
import tempfile
import threading
import time

from diffbot_sim.batch import run as run_mod


def run_local(runs, out_dir, batch_id, jobs, on_record):
    stop = threading.Event()
    node = socket.gethostname()
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
        futures = [pool.submit(run_mod.run_once, r, out_dir, batch_id, node, stop) for r in runs]
        try:
            for future in concurrent.futures.as_completed(futures):
                record = future.result()
                if record is not None:
                    on_record(record)
        except KeyboardInterrupt:
            stop.set()
            for f in futures:
                f.cancel()
            concurrent.futures.wait(futures)
            run_mod.end_processes(batch_id + "/")
            raise


# ------------------------------------------------------------------------------------------------------ Ray

def _pack(folder):
    buf = io.BytesIO()
    with tarfile.open(fileobj=buf, mode="w:gz") as tar:
        tar.add(folder, arcname=".")
    return buf.getvalue()


def _unpack(blob, folder):
    shutil.rmtree(folder, ignore_errors=True)
    os.makedirs(folder)
    with tarfile.open(fileobj=io.BytesIO(blob), mode="r:gz") as tar:
        # Our own packing, but checked all the same (Debian 12's Python 3.11.2 predates extractall's filter=):
        # regular files and folders inside the run's folder only.
        root = os.path.realpath(folder)
        members = [m for m in tar.getmembers() if (m.isfile() or m.isdir()) and
                   os.path.realpath(os.path.join(root, m.name)).startswith(root)]
        tar.extractall(folder, members=members)


def _ray_task(run, batch_id, attempt, tracker):
    """Body of a run's Ray task, on whichever node Ray chose."""
    import ray

    node_id = ray.get_runtime_context().get_node_id()
    ray.get(tracker.started.remote(run.name, node_id))
    work = tempfile.mkdtemp(prefix=_work_prefix(batch_id, run.name, attempt))
    try:
        record = run_mod.run_once(run, work, batch_id, node_id, attempt=attempt)
        return record, _pack(os.path.join(work, "runs", run.name))
    finally:
        shutil.rmtree(work, ignore_errors=True)


def _work_prefix(batch_id, name, attempt):
    """Prefix of a run attempt's work folder on its node (named so that a lost attempt's folder can be found)."""
    return f"diffbot_batch_{batch_id}_{name}_{attempt}_"


def _cleanup_task(marker, work_prefix=None):
    """End this node's processes carrying ``marker``; remove the work folders of a lost attempt, if named."""
    ended = run_mod.end_processes(marker)
    if work_prefix:
        for folder in glob.glob(os.path.join(glob.escape(tempfile.gettempdir()), glob.escape(work_prefix) + "*")):
            shutil.rmtree(folder, ignore_errors=True)
    return ended


class _Tracker:
    """Which node each run started on (so that a retry goes elsewhere)."""

    def __init__(self):
        self.nodes = {}

    def started(self, name, node_id):
        self.nodes[name] = node_id

    def node_of(self, name):
        return self.nodes.get(name)


def _alive_nodes(ray):
    return [n["NodeID"] for n in ray.nodes() if n.get("Alive")]


def _on_every_node(ray, marker, work_prefix=None):
    """End processes carrying ``marker`` on every live node (a task pinned to each), and remove work folders
    named ``work_prefix``."""
    from ray.util.scheduling_strategies import NodeAffinitySchedulingStrategy

    cleanup = ray.remote(num_cpus=0, max_retries=0)(_cleanup_task)
    refs = [cleanup.options(scheduling_strategy=NodeAffinitySchedulingStrategy(n, soft=False))
            .remote(marker, work_prefix) for n in _alive_nodes(ray)]
    try:
        ray.get(refs, timeout=60)
    except Exception:  # a node lost meanwhile: nothing of ours left running there
        pass


def run_ray(runs, out_dir, batch_id, address, on_record, say):
    """``address`` None: start a Ray instance on this machine (loopback, no dashboard) for the batch."""
    host = (address or "127.0.0.1").rsplit(":", 1)[0].strip("[]")
    if host in ("127.0.0.1", "localhost", "::1"):
        # Ray turns a loopback address into this machine's outward IP before connecting (for clusters that
        # span machines); a cluster bound to loopback is reached only if Ray keeps to loopback. Its switch for
        # that (read when ray is imported, so set first):
        os.environ.setdefault("RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER", "0")
    import ray
    from ray.exceptions import GetTimeoutError, NodeDiedError, RayTaskError, WorkerCrashedError
    from ray.util.scheduling_strategies import NodeAffinitySchedulingStrategy

    try:
        from ray.exceptions import ActorDiedError, ObjectLostError, OwnerDiedError
        lost = (WorkerCrashedError, NodeDiedError, ObjectLostError, OwnerDiedError, ActorDiedError)
    except ImportError:  # older Ray
        lost = (WorkerCrashedError, NodeDiedError)
    if address is None:
        # Ray reports usage statistics to its makers unless told not to; an instance we start for a batch is not
        # the user's to report on. (A cluster the user started follows its own `ray start` settings.)
        os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
        ray.init(include_dashboard=False, _node_ip_address="127.0.0.1", log_to_driver=False,
                 configure_logging=False)
        say(f"[batch] started a local Ray instance on 127.0.0.1 ({int(ray.cluster_resources().get('CPU', 0))} CPUs)")
    else:
        ray.init(address=address, log_to_driver=False, configure_logging=False)
        say(f"[batch] Ray cluster {address}: {len(_alive_nodes(ray))} nodes, "
            f"{int(ray.cluster_resources().get('CPU', 0))} CPUs")
    try:
        tracker = ray.remote(num_cpus=0)(_Tracker).remote()
        task = ray.remote(max_retries=0)(_ray_task)
        pending = {}  # ObjectRef -> (run, attempt)
        lost_on = {}  # run name -> node of its lost first attempt

        def submit(run, attempt, avoid=None):
            options = {"num_cpus": run.cpus}
            if avoid is not None:
                others = [n for n in _alive_nodes(ray) if n != avoid]
                if others:  # soft: if that node is full, Ray may still wait for it rather than fail
                    options["scheduling_strategy"] = NodeAffinitySchedulingStrategy(others[0], soft=True)
            pending[task.options(**options).remote(run, batch_id, attempt, tracker)] = (run, attempt)

        for r in runs:
            submit(r, 1)
        try:
            while pending:
                done, _ = ray.wait(list(pending), num_returns=1, timeout=1.0)
                for ref in done:
                    run, attempt = pending.pop(ref)
                    try:
                        record, blob = ray.get(ref)
                    except lost as err:
                        where = ray.get(tracker.node_of.remote(run.name))
                        _on_every_node(ray, f"{batch_id}/{run.name}/{attempt}",
                                       _work_prefix(batch_id, run.name, attempt))
                        if attempt == 1:
                            lost_on[run.name] = where or ""
                            say(f"[batch] {run.name}: its Ray worker or node was lost ({type(err).__name__}); "
                                f"running it again elsewhere")
                            submit(run, 2, avoid=where)
                            continue
                        record, blob = _lost_record(run, attempt, where, err), None
                    except RayTaskError as err:  # a fault of the runner itself on that node
                        record, blob = _lost_record(run, attempt, None, err), None
                    local = os.path.join(out_dir, "runs", run.name)
                    if blob is not None:
                        _unpack(blob, local)
                    record["log_dir"] = local
                    if run.name in lost_on:
                        record["retried_from"] = lost_on[run.name]  # the node whose worker was lost
                    on_record(record)
        except KeyboardInterrupt:
            for ref in pending:
                ray.cancel(ref, force=False)  # raises KeyboardInterrupt in the task: it ends its run's processes
            try:
                ray.wait(list(pending), num_returns=len(pending), timeout=15.0)
            except GetTimeoutError:
                pass
            _on_every_node(ray, batch_id + "/")
            raise
    finally:
        ray.shutdown()


def _lost_record(run, attempt, node, err):
    reason = f"Ray: {type(err).__name__}: {' '.join(str(err).split())[:300]}"
    return run_mod.make_record(run, "error", node or "", "", time.time(), 0.0, 0.0, 0, 1, reason, [], {}, attempt)
