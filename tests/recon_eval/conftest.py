"""Fixtures shared by the recon_eval tests."""
import pytest


@pytest.fixture(scope="session")
def plane_dataset(tmp_path_factory):
    """(path, {view: (Camera, cam_from_world)}) of the analytic plane dataset (written once)."""
    from _recon_eval_dataset import write_plane_dataset

    root = tmp_path_factory.mktemp("plane") / "ds"
    return root, write_plane_dataset(root)
