"""Which code computed a result: vic_drake's source hash, and the refusal of
Dask workers that run other code."""

import shutil

import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.experiments.dask_cluster import check_workers, worker_status
from vic_drake.provenance import CODE_ID_DIGITS, PACKAGE_DIR, code_id, source_hash


def test_the_source_hash_follows_the_modules_and_nothing_else(tmp_path):
    pkg = tmp_path / "vic_drake"
    shutil.copytree(PACKAGE_DIR, pkg, ignore=shutil.ignore_patterns("__pycache__"))
    first = source_hash(pkg)
    assert first == source_hash(PACKAGE_DIR) and len(first) == CODE_ID_DIGITS
    # Caches and other files do not count.
    (pkg / "__pycache__").mkdir(exist_ok=True)
    (pkg / "__pycache__" / "x.py").write_text("cached = 1\n")
    (pkg / "notes.txt").write_text("not code")
    assert source_hash(pkg) == first
    # One character of one module does.
    module = pkg / "control" / "tank.py"
    module.write_text(module.read_text() + "#\n")
    assert source_hash(pkg) != first
    module.rename(pkg / "control" / "tank2.py")  # So does a module's name.
    renamed = source_hash(pkg)
    assert renamed not in (first, source_hash(PACKAGE_DIR))


def test_the_code_id_names_the_source_drake_and_python():
    import platform

    from vic_drake import __version__

    here = code_id()
    assert here.startswith(f"vic_drake {__version__} source {source_hash()}, drake ")
    assert here.endswith(f", python {platform.python_version()}")


class _Client:
    """A cluster's client as check_workers sees it: ``ids`` by worker
    address; ``None`` for a worker whose vic_drake has no worker_status."""

    def __init__(self, ids: dict, problems: dict | None = None):
        self.status = {a: (c, (problems or {}).get(a, "")) for a, c in ids.items()}

    def scheduler_info(self):
        return {"workers": {a: {} for a in self.status}}

    def run(self, function, workers):
        assert function is worker_status  # Each worker reports its own.
        (addr,) = workers
        if self.status[addr][0] is None:
            raise AttributeError("Can't get attribute 'worker_status'")
        return {addr: self.status[addr]}


def test_workers_with_other_code_are_refused_by_name():
    here = code_id()
    check_workers(_Client({"tcp://a:1": here, "tcp://b:2": here}))
    other = "vic_drake 0.1.0 source 0123456789ab, drake 1.40.0, python 3.10.0"
    with pytest.raises(VicDrakeError) as err:
        check_workers(_Client({"tcp://a:1": here, "tcp://b:2": other}))
    text = str(err.value)
    assert text.startswith("1 Dask worker(s) run other code than this process")
    assert f"tcp://b:2: {other}" in text and "tcp://a:1" not in text
    assert here in text and "install the same vic_drake, Drake and Python" in text
    many = {f"tcp://w:{i}": other for i in range(5)}
    with pytest.raises(VicDrakeError, match=r"^5 Dask worker.*\(and 2 more\)"):
        check_workers(_Client(many))


def test_a_worker_that_would_fail_every_run_is_refused(monkeypatch):
    """A worker whose VIC_DRAKE_ALLOCATOR is bad fails each run at once, so
    it takes the whole queue: refused when the cluster is reached."""
    monkeypatch.setenv("VIC_DRAKE_ALLOCATOR", "bogus")
    code, problem = worker_status()
    assert code == code_id() and "VIC_DRAKE_ALLOCATOR='bogus'" in problem
    monkeypatch.delenv("VIC_DRAKE_ALLOCATOR")
    assert worker_status() == (code_id(), "")
    here = code_id()
    client = _Client({"tcp://a:1": here, "tcp://b:2": here}, {"tcp://b:2": problem})
    with pytest.raises(VicDrakeError) as err:
        check_workers(client)
    assert str(err.value).startswith("1 Dask worker(s) cannot run scans: tcp://b:2: ")
    assert "mend their environment" in str(err.value)


def test_a_worker_on_an_older_vic_drake_is_refused_not_a_traceback():
    """Dask sends worker_status by name: a worker whose vic_drake predates it
    fails the call. It runs other code, and is refused as such."""
    here = code_id()
    with pytest.raises(VicDrakeError) as err:
        check_workers(_Client({"tcp://a:1": here, "tcp://old:2": None}))
    text = str(err.value)
    assert text.startswith("1 Dask worker(s) run other code than this process")
    assert (
        "tcp://old:2: not this vic_drake (worker_status failed: AttributeError)" in text
    )
