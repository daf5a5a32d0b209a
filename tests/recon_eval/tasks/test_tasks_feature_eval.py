"""The feature evaluation's pair description rules that need no rendering (series names, lighting)."""
from recon_eval.tasks.feature_eval import lighting_changed, series_name


def test_series_and_lighting_from_view_entries():
    assert series_name("tilt_0003", {}) == "tilt"
    assert series_name("st_left_0012", {}) == "st_left"
    assert series_name("tilt_0003", {"view_set": "viewpoint"}) == "viewpoint"
    assert lighting_changed({}, {"lights": {}}) is None
    assert lighting_changed({"lights": {"sun": {"intensity": 1}}}, {"lights": {"sun": {"intensity": 1}}}) is False
    assert lighting_changed({"lights": {"sun": {"intensity": 1}}}, {"lights": {"sun": {"intensity": 2}}}) is True
