# SPDX-License-Identifier: Apache-2.0
"""inertialnet.batch: the CLI's batch files and resume rule from Python, locally and on a Ray cluster
(issue 25). The Ray tests run wherever ray is importable, and always in CI (CI=true): there a
missing ray is a failure, not a skip."""
import os
import pathlib
import shutil

import pytest

import inertialnet
from inertialnet import batch

NAMES = ("s1", "s2", "s3")


def _ray():
    try:
        return batch._import_ray()
    except ImportError:
        if os.environ.get("CI") == "true":
            raise  # CI installs the [ray] extra: its absence is a failure there
        pytest.skip("ray is not installed (pip install '.[ray]')")


@pytest.fixture(scope="module")
def three(tmp_path_factory):
    """Three small synthetic EuRoC sequences; s2 the longest (about a second of work), so that its
    task reports progress before its end (the Ray test kills its worker there)."""
    root = tmp_path_factory.mktemp("batch")
    assert inertialnet.synth(root / "s1", frames=5, width=96, height=64, seed=1) == 5
    assert inertialnet.synth(root / "s2", frames=20, width=320, height=240, seed=2) == 20
    assert inertialnet.synth(root / "s3", frames=5, width=96, height=64, seed=3) == 5
    return root


def _files(folder):
    """Every output's bytes by file name (CSV and sidecar)."""
    return {p.name: p.read_bytes() for p in sorted(pathlib.Path(folder).iterdir())}


def _times(folder):
    return {p.name: p.stat().st_mtime_ns for p in sorted(pathlib.Path(folder).iterdir())}


@pytest.fixture(scope="module")
def cli_batch(three, cli):
    """`inertialnet predict s1 s2 s3 -o cli_out`, the reference of every Python batch."""
    cli("predict", *NAMES, "-o", "cli_out", cwd=three)
    return _files(three / "cli_out")


def test_local_batch_equals_cli_and_resumes(three, cli_batch):
    out = three / "py_out"
    seen = []
    results = batch.predict([three / n for n in NAMES], out, progress=seen.append)
    assert [r["status"] for r in results] == ["computed"] * 3
    assert [r["name"] for r in seen] == list(NAMES)
    assert _files(out).keys() == cli_batch.keys()
    for name, data in _files(out).items():
        # The sidecar's provenance names the sequence by its absolute path: the same here.
        assert data == cli_batch[name], name
    before = _times(out)
    again = batch.predict(str(three / "s*"), out)  # a glob: the same three, sorted
    assert [r["status"] for r in again] == ["skipped"] * 3
    assert _times(out) == before
    changed = batch.predict([three / n for n in NAMES], out, flow_check=0.25)
    assert [r["status"] for r in changed] == ["computed"] * 3
    assert "flow_check_px" in changed[0]["reason"]


def test_evaluate_table(three, cli, cli_batch):
    table = batch.evaluate(three / "cli_out", [three / n for n in NAMES], format="csv")
    # The same library call as the CLI's: the same numbers to the digit.
    assert table == cli("eval", "cli_out", "--seq", *NAMES, "--format", "csv", cwd=three, stdout_only=True)
    lines = table.splitlines()
    assert len(lines) == 5 and lines[-1].startswith("total,30,"), lines
    assert lines[-1].split(",")[3] == "27"  # evaluated pairs: 4 + 19 + 4
    with pytest.raises(ValueError, match="is named s3"):
        batch.evaluate(three / "cli_out", [three / "s1", three / "s2"])


def test_bad_batches(three):
    other = three / "other"
    shutil.copytree(three / "s1", other / "s1", dirs_exist_ok=True)
    with pytest.raises(ValueError, match="would both write"):
        batch.predict([three / "s1", other / "s1"], three / "dup")
    with pytest.raises(ValueError, match="matches no sequence"):
        batch.predict(str(three / "nothing*"), three / "none")


def test_missing_sequence_refused_before_any_is_computed(three):
    """A missing sequence stops the batch before the first is computed (it stopped it at its turn,
    after the others' work), a manifest's one named manifest:line, as the CLI does."""
    with pytest.raises(ValueError, match=r"the sequence .*gone does not exist; nothing was computed"):
        batch.predict([three / "s1", three / "gone"], three / "early")
    assert not (three / "early" / "s1.csv").exists()
    manifest = three / "early.txt"
    manifest.write_text("# two sequences\ns1\n\ngone2\n")
    with pytest.raises(ValueError, match=r"early\.txt:4: it lists the sequence .*gone2, which does not exist"):
        batch.predict(str(manifest), three / "early_manifest")
    assert not (three / "early_manifest" / "s1.csv").exists()


def test_ray_cluster_survives_a_killed_worker_and_resumes(three, cli_batch, tmp_path):
    """A local cluster of two worker CPUs; the worker computing s2 kills itself (SIGKILL) in the
    middle of the sequence on the first try, leaving s2.csv.partial: Ray retries the task, and the
    batch ends with the CLI's files, byte for byte. A second batch computes nothing."""
    ray = _ray()
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=True)
    try:
        out = three / "ray_out"
        marker = str(tmp_path / "s2_killed_once")

        def kill_s2_once(name, done, total):
            # Runs in the worker: its process dies mid-sequence, as a machine lost would.
            import os as _os
            import signal as _signal
            if name == "s2" and 0 < done < total and not _os.path.exists(marker):
                with open(marker, "w") as f:
                    f.write(f"{done} {total}")
                _os.kill(_os.getpid(), _signal.SIGKILL)

        results = batch.predict([three / n for n in NAMES], out, cluster="auto", max_retries=2,
                                task_progress=kill_s2_once)
        assert os.path.exists(marker), "the worker of s2 was not killed"
        done, total = map(int, open(marker).read().split())
        assert 0 < done < total  # killed with rows in s2.csv.partial, before its end
        assert [r["status"] for r in results] == ["computed"] * 3
        assert not (out / "s2.csv.partial").exists()
        files = _files(out)
        assert files.keys() == cli_batch.keys()
        for name, data in files.items():
            assert data == cli_batch[name], name
        before = _times(out)
        again = batch.predict([three / n for n in NAMES], out, cluster="auto")
        assert [r["status"] for r in again] == ["skipped"] * 3
        assert _times(out) == before
    finally:
        ray.shutdown()
