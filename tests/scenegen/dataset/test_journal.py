"""The manifest's journal (scenegen/dataset/journal.py): O(1) recording, compaction into the same
manifest.json, and every state a crash (or a damaged disk) can leave it in."""
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest
import trimesh

from scenegen import dataset as ds
from scenegen.dataset import journal
from scenegen.dataset.layout import MANIFEST, MANIFEST_JOURNAL

sys.path.insert(0, str(Path(__file__).parent))  # the dataset fixtures of test_dataset.py
from test_dataset import SPEC, VIEWS, all_bytes, make_view, new_writer, view_cameras, write_dataset


@pytest.fixture(scope="module")
def complete(tmp_path_factory):
    out = tmp_path_factory.mktemp("journal_complete") / "out"
    write_dataset(out)
    return out


def crashed_after(out: Path, n_views: int):
    """A writer that recorded ``n_views`` views and then 'died' (never closed): the journal holds
    them, manifest.json only the declared views."""
    w = new_writer(out)
    w.write_cameras(view_cameras(), SPEC)
    w.write_mesh("box", trimesh.creation.box(extents=(1, 2, 3)))
    for v in VIEWS[:n_views]:
        w.write_view(v, **make_view(VIEWS.index(v)))
    w.abort()  # the kernel releases a killed process's lock; the journal stays as it was
    return w  # never closed: manifest.json + journal, as a killed process leaves them


def resume_to_end(out: Path):
    write_dataset(out, writer=new_writer(out, resume=True))


def journal_lines(out: Path) -> list[bytes]:
    return (out / MANIFEST_JOURNAL).read_bytes().splitlines(keepends=True)


def test_finished_dataset_has_no_journal_and_its_manifest_is_rewritten_only_at_the_end(tmp_path, complete):
    out = tmp_path / "b"
    w = new_writer(out)
    w.write_cameras(view_cameras(), SPEC)
    declared = (out / MANIFEST).read_bytes()
    ino = (out / MANIFEST).stat().st_ino
    for v in VIEWS:
        w.write_view(v, **make_view(VIEWS.index(v)))
        # recording a view touches the journal, never manifest.json (O(1) per view)
        assert (out / MANIFEST).stat().st_ino == ino and (out / MANIFEST).read_bytes() == declared
    w.write_mesh("box", trimesh.creation.box(extents=(1, 2, 3)))
    assert ds.load_current_manifest(out)["files"] == w.manifest["files"]
    w.close()
    assert not (out / MANIFEST_JOURNAL).exists()
    assert all_bytes(out) == all_bytes(complete)
    assert ds.verify(out).ok


def test_journal_line_size_does_not_grow_with_the_run(tmp_path):
    w = ds.DatasetWriter(tmp_path / "o", spec_sha256="a" * 64, seed=0, variant="v", versions={})
    names = [f"v{i:05d}" for i in range(300)]
    w.write_cameras({n: {"camera": {}, "cam_from_world": {}} for n in names}, {})
    sizes = []
    for i, n in enumerate(names):
        before = w.journal_bytes
        w.record_view(n, {rel: f"{i:064x}" for rel in ds.view_paths(n).values()})
        sizes.append(w.journal_bytes - before)
    # the same bytes per view but the digits of the line number (the first also carries the header)
    assert len({size - len(str(i + 1)) for i, size in enumerate(sizes[1:], start=1)}) == 1
    w.close()
    assert not (tmp_path / "o" / MANIFEST_JOURNAL).exists()


def test_crash_between_journal_lines_then_resume(tmp_path, complete):
    out = tmp_path / "b"
    crashed_after(out, 3)
    assert len(journal_lines(out)) == 1 + 1 + 3  # header, mesh, three views
    d = ds.Dataset(out)  # readable after the crash: manifest.json + journal
    assert d.views == tuple(VIEWS[:3])
    rep = ds.verify(out)
    assert not rep.ok and rep.missing == rep.corrupted == rep.unexpected == ()
    assert rep.incomplete_views == tuple(sorted(VIEWS[3:]))
    assert any("did not finish" in p for p in rep.problems)
    w = new_writer(out, resume=True)
    assert [w.is_complete(v) for v in VIEWS] == [True] * 3 + [False] * 2
    assert not (out / MANIFEST_JOURNAL).exists()  # compacted on resume
    write_dataset(out, writer=w)
    assert all_bytes(out) == all_bytes(complete) and ds.verify(out).ok


@pytest.mark.parametrize("cut", ["half_line", "no_newline", "zeros"])
def test_torn_last_line_is_dropped_and_its_view_rendered_again(tmp_path, complete, cut):
    out = tmp_path / "b"
    crashed_after(out, 3)
    lines = journal_lines(out)
    last = lines[-1]
    torn = {"half_line": last[: len(last) // 2], "no_newline": last[:-1], "zeros": b"\0" * len(last)}[cut]
    (out / MANIFEST_JOURNAL).write_bytes(b"".join(lines[:-1]) + torn)
    assert ds.Dataset(out).views == tuple(VIEWS[:2])  # the third view's record did not make it
    rep = ds.verify(out)
    assert not rep.ok and any("incomplete last line" in p for p in rep.problems)
    assert len(rep.unexpected) == 5  # the third view's files: on disk, not recorded
    w = new_writer(out, resume=True)
    assert [w.is_complete(v) for v in VIEWS] == [True, True, False, False, False]
    write_dataset(out, writer=w)
    assert all_bytes(out) == all_bytes(complete) and ds.verify(out).ok


def test_flipped_byte_in_the_last_line_counts_as_torn(tmp_path, complete):
    out = tmp_path / "b"
    crashed_after(out, 3)
    data = bytearray((out / MANIFEST_JOURNAL).read_bytes())
    data[-10] ^= 0x01
    (out / MANIFEST_JOURNAL).write_bytes(bytes(data))
    assert any("incomplete last line" in p for p in ds.verify(out).problems)
    resume_to_end(out)
    assert all_bytes(out) == all_bytes(complete)


@pytest.mark.parametrize("damage", ["flip", "swap", "duplicate", "drop"])
def test_corrupt_line_before_valid_ones_is_refused(tmp_path, damage):
    out = tmp_path / "b"
    crashed_after(out, 4)
    lines = journal_lines(out)
    if damage == "flip":
        bad = bytearray(lines[2])
        bad[5] ^= 0x20
        lines[2] = bytes(bad)
    elif damage == "swap":
        lines[2], lines[3] = lines[3], lines[2]
    elif damage == "duplicate":
        lines.insert(3, lines[3])
    else:
        del lines[2]
    (out / MANIFEST_JOURNAL).write_bytes(b"".join(lines))
    before = all_bytes(out)
    with pytest.raises(ds.DatasetError, match=MANIFEST_JOURNAL):
        new_writer(out, resume=True)
    with pytest.raises(ds.DatasetError, match="cannot be trusted"):
        ds.Dataset(out)
    rep = ds.verify(out)
    assert not rep.ok and any("cannot be trusted" in p for p in rep.problems)
    assert all_bytes(out) == before  # nothing touched


def test_journal_without_a_manifest_is_refused(tmp_path):
    out = tmp_path / "b"
    crashed_after(out, 2)
    (out / MANIFEST).unlink()
    with pytest.raises(ds.DatasetError, match="manifest was removed"):
        new_writer(out, resume=True)
    with pytest.raises(ds.DatasetError, match="manifest was removed"):
        new_writer(out)
    with pytest.raises(ds.DatasetError, match="manifest was removed"):
        ds.Dataset(out)
    rep = ds.verify(out)
    assert not rep.ok and rep.missing == (MANIFEST,) and "manifest was removed" in rep.problems[0]


def test_journal_of_another_manifest_is_refused(tmp_path):
    out = tmp_path / "b"
    w = crashed_after(out, 2)
    older = (out / MANIFEST).read_bytes()
    w2 = new_writer(out, resume=True)  # compacts: manifest.json now lists the two views
    w2.write_view(VIEWS[2], **make_view(2))  # a new journal, extending the new manifest
    w2.abort()  # killed
    (out / MANIFEST).write_bytes(older)  # someone puts the old manifest back
    with pytest.raises(ds.DatasetError, match="extends another"):
        new_writer(out, resume=True)
    assert w is not None


def test_stale_journal_after_a_crash_during_compaction_is_dropped(tmp_path, complete):
    out = tmp_path / "b"
    w = crashed_after(out, 5)
    stale = (out / MANIFEST_JOURNAL).read_bytes()
    w2 = new_writer(out, resume=True)  # compacts and removes the journal
    w2.abort()  # killed
    (out / MANIFEST_JOURNAL).write_bytes(stale)  # as if killed between the rewrite and the unlink
    assert ds.Dataset(out).views == tuple(VIEWS)
    write_dataset(out, writer=new_writer(out, resume=True))
    assert all_bytes(out) == all_bytes(complete)
    assert w is not None and w2 is not None


def test_parse_journal_units():
    h = journal.encode_line(0, journal.header("f" * 64))
    r1 = journal.encode_line(1, journal.file_record("a/b.json", "0" * 64))
    j = journal.parse_journal(h + r1)
    assert j.manifest_sha256 == "f" * 64 and j.records[0]["path"] == "a/b.json" and j.torn_lines == 0
    assert journal.parse_journal(h + r1[:7]).torn_lines == 1
    assert journal.parse_journal(h[:10]).records == [] and journal.parse_journal(b"").torn_lines == 0
    with pytest.raises(ds.DatasetError, match="header"):
        journal.parse_journal(journal.encode_line(0, journal.file_record("x", "0" * 64)) + r1)
    with pytest.raises(ds.DatasetError, match="unknown record"):
        journal.parse_journal(h + journal.encode_line(1, {"op": "delete"}))


_KILLED_IN_A_JOURNAL_WRITE = r"""
import os, sys, time
sys.path.insert(0, sys.argv[2])
from scenegen.dataset import journal
import test_dataset as t

real = journal.JournalAppender.append
count = [0]

def torn(self, records):
    count[0] += 1
    if count[0] < 5:  # the header, the mesh, two views: the third view's line is cut
        return real(self, records)
    data = b"".join(journal.encode_line(self._n + i, r) for i, r in enumerate(records))
    os.write(self._fd, data[: len(data) // 2])
    os.fsync(self._fd)
    print("HALF", flush=True)
    time.sleep(60)

journal.JournalAppender.append = torn
t.write_dataset(t.Path(sys.argv[1]))
print("finished")
"""


def test_sigkill_inside_a_journal_write_then_resume(tmp_path, complete):
    """A real SIGKILL while a journal line is half written: resume gives the uninterrupted bytes."""
    out = tmp_path / "b"
    proc = subprocess.Popen([sys.executable, "-c", _KILLED_IN_A_JOURNAL_WRITE, str(out), str(Path(__file__).parent)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        assert proc.stdout.readline().strip() == b"HALF", proc.stderr.read()[-2000:]
    finally:
        os.kill(proc.pid, signal.SIGKILL)
        proc.communicate()
    assert proc.returncode == -signal.SIGKILL
    assert not journal_lines(out)[-1].endswith(b"\n")  # a torn line on disk
    assert ds.Dataset(out).views == tuple(VIEWS[:2])
    resume_to_end(out)
    assert all_bytes(out) == all_bytes(complete) and ds.verify(out).ok


def test_manifest_bytes_encode_once_as_defined():
    """manifest_bytes encodes the body once and inserts the hash line: the defined bytes."""
    from scenegen.dataset.codecs.json import encode_json
    from scenegen.dataset.files import sha256_bytes
    from scenegen.dataset.manifest import manifest_bytes

    def defined(body):
        return encode_json({**body, "manifest_sha256": sha256_bytes(encode_json(body))})

    views = {f"v{i}": {"status": "complete", "files": [f"a/{i}.png"]} for i in range(3)}
    base = {"format": "f", "format_version": 1, "seed": 3, "spec_sha256": "0" * 64, "variant": "v",
            "versions": {"seed": "x"}, "views": views, "files": {f"a/{i}.png": "0" * 64 for i in range(3)}}
    for body in (base, {**base, "nested": {"seed": 1}}, {**base, "r": 1}, {k: v for k, v in base.items() if k != "seed"},
                 {"seed": 1}, {}):
        assert manifest_bytes(body) == defined(body)


def test_atomic_write_files_all_or_renamed_complete(tmp_path, monkeypatch):
    """A view's files: written and fsync'd, renamed, directories fsync'd once; a failure leaves
    only complete renamed files and no temporary file."""
    from scenegen.dataset import files

    items = {tmp_path / "a" / f"f{i}.bin": bytes([i]) * (1000 + i) for i in range(4)}
    items[tmp_path / "b" / "g.bin"] = b"g" * 10
    synced = []
    monkeypatch.setattr(files, "fsync_dir", lambda d: synced.append(d))
    files.atomic_write_files(items)
    assert all(p.read_bytes() == d for p, d in items.items())
    assert sorted(synced) == [tmp_path / "a", tmp_path / "b"]  # once per directory
    real, n = os.replace, []

    def dying(src, dst):
        n.append(dst)
        if len(n) == 3:
            raise KeyboardInterrupt
        real(src, dst)

    monkeypatch.setattr(os, "replace", dying)
    new = {p.with_name("new_" + p.name): b"new" + d for p, d in items.items()}
    with pytest.raises(KeyboardInterrupt):
        files.atomic_write_files(new)
    monkeypatch.setattr(os, "replace", real)
    done = [p for p in new if p.exists()]
    assert len(done) == 2 and all(p.read_bytes() == new[p] for p in done)
    assert not list(tmp_path.rglob(f"*{files.TEMP_SUFFIX}"))
