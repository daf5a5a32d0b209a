"""The leaderboard page (one sortable table per task, best value per column and scene, gate
colours, links, skipped methods) and the summary that opens every HTML report; hostile text is
escaped and nothing is loaded from outside the file."""
import re
from types import SimpleNamespace

import pytest

from recon_eval.report.html import render_html
from recon_eval.report.leaderboard_html import html_page
from recon_eval.report.summary import higher_is_better, summary_rows
from recon_eval.runners import FAULTS, METHODS, TASKS

EVIL = '<script>alert("x")</script>'


def _run(scene, method, task, **metrics):
    return {"command": "run", "inputs": {"scene": scene, "method": method, "task": task}, "results": {},
            "metrics": metrics}


def _doc():
    runs = [_run("s1", "a", "fundamental matrix", sampson_rms_px=0.5, inlier_recall=0.9),
            _run("s1", "b", "fundamental matrix", sampson_rms_px=0.2, inlier_recall=0.8),
            _run("s2", "a", "fundamental matrix", sampson_rms_px=3.0, inlier_recall="nan"),
            _run("s1", EVIL, "stereo disparity", bad_2_0_noc_pct=7.5)]
    return {"command": "leaderboard", "runs": runs, "run_dirs": ["s1/a", "s1/b", "s2/a", "s1/x y"],
            "skipped": [{"scene": "s2", "method": "c", "why": f"no stereo pairs {EVIL}"}]}


def _cells(page, task):
    table = page.split(f"<h2>{task}</h2>", 1)[1].split("</table>", 1)[0]
    rows = [re.findall(r"<td([^>]*)>(.*?)</td>", row) for row in re.findall(r"<tr>(.*?)</tr>", table)]
    return [r for r in rows if r]  # the header row has no td


def test_one_table_per_task_one_column_per_metric():
    page = html_page(_doc())
    assert page.count("<table>") == 3  # two tasks and the skipped list
    head = page.split("<h2>fundamental matrix</h2>", 1)[1].split("</thead>", 1)[0]
    assert re.findall(r'<th title="([^"]+)"', head) == ["sampson_rms_px", "inlier_recall"]
    rows = _cells(page, "fundamental matrix")
    assert [r[1][1] for r in rows] == ["a", "b", "a"]


def test_best_value_per_column_within_each_scene():
    rows = _cells(page := html_page(_doc()), "fundamental matrix")
    best = [[("best" in attrs) for attrs, _ in r[2:4]] for r in rows]
    # s1: b has the lower Sampson, a the higher recall; s2 alone: its finite Sampson is best, its NaN recall is not
    assert best == [[False, True], [True, False], [True, False]]
    assert "nan" in rows[2][3][1] and page.count("<script>") == 1


def test_gate_colours_and_links():
    doc = _doc()
    gate = SimpleNamespace(metric="sampson_rms_px", op="<=", threshold=1.0, where="g.yaml:3")
    outcomes = [SimpleNamespace(gate=gate, passed=True, value=0.5, result_file="lb.json#runs[0]"),
                SimpleNamespace(gate=gate, passed=False, value=3.0, result_file="lb.json#runs[2]")]
    rows = _cells(html_page(doc, outcomes), "fundamental matrix")
    assert "pass" in rows[0][2][0] and "fail" in rows[2][2][0] and "pass" not in rows[1][2][0]
    assert 'href="s1/a/report.html"' in rows[0][4][1] and 'href="s1/a/result.json"' in rows[0][4][1]
    assert 'href="s1/x%20y/report.html"' in html_page(doc)


def test_hostile_text_is_escaped_and_nothing_is_external():
    page = html_page(_doc())
    assert EVIL not in page and "&lt;script&gt;alert(&quot;x&quot;)&lt;/script&gt;" in page
    assert "Skipped" in page and "no stereo pairs &lt;script&gt;" in page
    assert not re.search(r'(src|href)="(https?:)?//', page) and "<link" not in page


def test_summary_of_a_scoring_command_colours_failures():
    results = {"fundamental": {"sampson_rms_px": "inf", "failed": True, "failure_reason": "rank 3"},
               "zhang_f_distance": {"f_distance_px": 0.5, "failed": False}, EVIL: {"x": 1.0}}
    rows = summary_rows({"command": "fmatrix", "inputs": {}, "results": results})
    assert [(r.name, r.status) for r in rows] == [("fundamental", "fail"), ("zhang_f_distance", "ok"), (EVIL, "info")]
    assert rows[0].note == "failed: rank 3"
    page = render_html("fmatrix", {"method": EVIL}, results, [])
    assert EVIL not in page and page.index("<h2>Summary</h2>") < page.index("<h2>Results</h2>")
    assert 'class="verdict fail"' in page and '<tr class="fail"><td class="status">fail</td>' in page


def test_summary_of_a_run_lists_failed_invocations():
    doc = {"command": "run", "inputs": {"notes": {"a__b": {"failed": "exit status 3", "stderr_tail": ["boom"]}}},
           "results": {}, "metrics": {"sampson_rms_px": "inf"}}
    rows = summary_rows(doc)
    assert [(r.name, r.status, r.note) for r in rows] == [("sampson_rms_px", "fail", ""),
                                                          ("a__b", "fail", "exit status 3: boom")]


def test_one_failed_invocation_is_one_row_and_the_inputs_are_words_not_reprs():
    """A pair whose command crashed left four numbers at inf in two result groups: the summary
    shows one FAIL row for it (the other pair's rows stay), the inputs table no Python dict."""
    notes = {"a__b": {"failed": "exit status 1", "stderr_tail": ["Traceback", "boom"], "argv": ["python", "m.py"]},
             "a__b.truth": {"pixels": "distorted"}}
    doc = {"command": "run", "inputs": {"method": "mine", "notes": notes},
           "metrics": {"a__b.sampson_rms_px": "inf", "a__b.pose_err_deg": "inf", "a__c.sampson_rms_px": 0.4},
           "results": {"a__b.fundamental": {"sampson_rms_px": "inf", "failed": True, "failure_reason": "non-finite"},
                       "a__b.pose_via_K": {"pose_err_deg": "inf", "failed": True, "failure_reason": "non-finite"},
                       "a__c.fundamental": {"sampson_rms_px": 0.4, "failed": False}}}
    rows = summary_rows(doc)
    assert [(r.name, r.status) for r in rows] == [("a__c.sampson_rms_px", "info"), ("a__c.fundamental", "ok"),
                                                  ("a__b", "fail")]
    assert rows[-1].note == "exit status 1: boom (no estimate: 4 result rows folded into this one)"
    page = render_html("run", doc["inputs"], doc["results"], [], metrics=doc["metrics"])
    assert page.count('<tr class="fail">') == 1
    assert "{&#x27;" not in page and "[&#x27;" not in page  # no repr of a dict or a list
    assert "<td>notes.a__b.argv</td><td>python m.py</td>" in page and "<td>notes.a__b.truth.pixels</td>" in page


@pytest.mark.parametrize("metric, higher", [
    ("synthetic.sampson_rms_px", False), ("sift.inlier_recall", True), ("bad_2_0_noc_pct", False),
    ("invalid_noc_pct", False), ("registration_ratio", True), ("points.failure_ratio", False),
    ("max_rot_err_deg", False), ("mma_3", True), ("tilt.repeatability", True), ("matching_score", True),
    ("n_points3d", True), ("cloud_precision_at_1cm", True), ("fx_rel_err", False), ("synthetic.floor.mace_px", False),
    ("views_used_ratio", True), ("abs_median_signed_err_px", False), ("sigma1.median_rel_err", False),
    ("localisation_err_px", False), ("calib_rms_px", False), ("median_signed_err_px", None),
    ("description", None), ("lambertian.within_10deg", True), ("all.albedo_rel_mae", False), ("coverage", True),
    ("lambertian.mean_ae_deg", False), ("bop19_ar", True), ("bop19_ar_mspd", True), ("coco_kp_ap50", True),
    ("pck_10", True), ("median_joint_rot_err_deg", False),
])
def test_direction_of_the_leaderboard_metrics(metric, higher):
    assert higher_is_better(metric) is higher


def test_every_method_has_a_named_task():
    for m in [*METHODS.values(), *FAULTS.values()]:
        assert m.task in TASKS.values(), m.name
