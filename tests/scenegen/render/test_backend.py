"""The libLLVM the LLVM back end is pointed at: any >= 16 under the names Debian, Ubuntu and
apt.llvm.org give it, the newest first, never 15 (it aborts the process: docs/conventions.md)."""
import pytest

from scenegen.render.backend import MIN_LLVM_MAJOR, find_libllvm, llvm_major


@pytest.mark.parametrize("path,major", [
    ("/usr/lib/x86_64-linux-gnu/libLLVM-15.so.1", 15),      # Debian 12, Ubuntu 22.04 libllvm15
    ("/usr/lib/x86_64-linux-gnu/libLLVM-16.so.1", 16),      # Debian 12 libllvm16
    ("/usr/lib/x86_64-linux-gnu/libLLVM-17.so.1", 17),      # Ubuntu 24.04 libllvm17
    ("/usr/lib/x86_64-linux-gnu/libLLVM.so.18.1", 18),      # Ubuntu 24.04 libllvm18
    ("/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1", 19),      # Debian 13 libllvm19
    ("/usr/lib/aarch64-linux-gnu/libLLVM.so.20.1", 20),
    ("/usr/lib/llvm-17/lib/libLLVM-17.so", 17),             # llvm-17-dev
    ("/usr/lib/llvm-20/lib/libLLVM.so.1", 20),              # the version only in the folder
    ("/usr/local/lib/libLLVM.so", None),
])
def test_the_major_version_of_each_distribution_name(path, major):
    assert llvm_major(path) == major


def _tree(tmp_path, names):
    for n in names:
        p = tmp_path / n
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_bytes(b"")
    return (str(tmp_path / "x86_64-linux-gnu/libLLVM*.so*"), str(tmp_path / "llvm-*/lib/libLLVM*.so*"))


def test_the_newest_suitable_library_is_taken_and_15_never(tmp_path):
    pats = _tree(tmp_path, ["x86_64-linux-gnu/libLLVM-15.so.1", "x86_64-linux-gnu/libLLVM-16.so.1",
                            "x86_64-linux-gnu/libLLVM.so.18.1", "llvm-17/lib/libLLVM-17.so.1"])
    assert find_libllvm(pats) == str(tmp_path / "x86_64-linux-gnu/libLLVM.so.18.1")
    assert llvm_major(find_libllvm(pats)) >= MIN_LLVM_MAJOR


def test_a_version_named_only_by_its_folder_is_found(tmp_path):
    pats = _tree(tmp_path, ["x86_64-linux-gnu/libLLVM-16.so.1", "llvm-20/lib/libLLVM.so.1"])
    assert find_libllvm(pats) == str(tmp_path / "llvm-20/lib/libLLVM.so.1")


def test_only_libllvm_15_means_none(tmp_path):
    pats = _tree(tmp_path, ["x86_64-linux-gnu/libLLVM-15.so.1", "llvm-15/lib/libLLVM-15.so.1"])
    assert find_libllvm(pats) is None
