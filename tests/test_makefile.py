"""`make llvm` (run by `make setup`) on machines that have, or lack, Debian/Ubuntu's libLLVM
packages, simulated with a fake dpkg and apt-get on PATH: any libllvm16..21 is taken, and a
machine without one gets a warning and exit 0, never an abort (README: the scalar_rgb fallback)."""
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
MAKE = shutil.which("make")
pytestmark = pytest.mark.skipif(MAKE is None, reason="no make on this machine")


def _fake(bin_dir: Path, name: str, body: str) -> None:
    p = bin_dir / name
    p.write_text("#!/bin/sh\n" + body)
    p.chmod(0o755)


def run_llvm(tmp_path, *, installed=(), installable=(), apt=True):
    """`make llvm` with PATH holding only fake tools: dpkg -s says yes for ``installed``;
    apt-get install succeeds for ``installable``; every apt-get call is logged."""
    fake = tmp_path / "bin"
    fake.mkdir()
    log = tmp_path / "apt.log"
    _fake(fake, "id", "echo 0\n")  # the Makefile asks whether it runs as root (then no sudo)
    _fake(fake, "dpkg", f'for p in {" ".join(installed) or "none"}; do [ "$2" = "$p" ] && exit 0; done; exit 1\n')
    if apt:
        _fake(fake, "apt-get", f'echo "$@" >> {log}\n[ "$1" = update ] && exit 0\n'
                               f'for p in {" ".join(installable) or "none"}; do [ "$4" = "$p" ] && exit 0; done\n'
                               'echo "E: Unable to locate package $4" >&2; exit 100\n')
    r = subprocess.run([MAKE, "-s", "-C", str(ROOT), "llvm", "SUDO="], env={"PATH": str(fake)},
                       capture_output=True, text=True, timeout=60)
    calls = log.read_text().splitlines() if log.exists() else []
    return r, calls


def test_an_installed_libllvm_of_any_suitable_version_is_taken(tmp_path):
    r, calls = run_llvm(tmp_path, installed=("libllvm17",))
    assert r.returncode == 0 and calls == [] and r.stderr == "", (r.stdout, r.stderr)


def test_the_first_installable_version_is_installed(tmp_path):
    r, calls = run_llvm(tmp_path, installable=("libllvm18",))
    assert r.returncode == 0, r.stderr
    assert "installed libllvm18" in r.stdout
    assert [c.split()[-1] for c in calls] == ["libllvm19", "libllvm20", "libllvm21", "libllvm18"]


def test_no_package_anywhere_is_a_warning_not_an_abort(tmp_path):
    r, calls = run_llvm(tmp_path)
    assert r.returncode == 0, r.stderr
    assert r.stderr.startswith("warning: apt-get could install none of libllvm19") and "scalar_rgb" in r.stderr
    assert "update -qq" in calls  # tried again after refreshing the package lists
    assert not any("libllvm15" in c for c in calls)  # 15 aborts the process: never asked for


def test_no_apt_get_is_a_warning_not_an_abort(tmp_path):
    r, calls = run_llvm(tmp_path, apt=False)
    assert r.returncode == 0 and r.stderr.startswith("warning: no apt-get") and calls == []
