"""The agreement tests: each metric against its reference tool on the same input.

Every test here measures the largest difference between recon_eval's number and the reference's
(the reference's own code where it installs from the package registry, e.g. evo; otherwise its
algorithm transcribed in the test with the source named) and records it with the ``agreement``
fixture. The table between the markers in docs/metrics.md is made from these records:

* ``RECON_EVAL_WRITE_AGREEMENT=1 pytest tests/recon_eval/agreement`` rewrites the rows it
  measured (others are kept, new ones appended);
* otherwise every test checks that its row is in the table and that the measured difference is
  at most the documented one (so the table stays what the tests measure).
"""
from __future__ import annotations

import math
import os
import re
from pathlib import Path

import pytest

DOC = Path(__file__).resolve().parents[3] / "docs" / "metrics.md"
BEGIN, END = "<!-- agreement:begin -->", "<!-- agreement:end -->"
HEADER = ("| id | metric | reference tool (version) | input | measured difference |\n"
          "|---|---|---|---|---|")
_ROWS: dict[str, tuple] = {}


def bound_text(x: float) -> str:
    """The measured difference rounded UP to one significant digit ('0' when exact)."""
    if x == 0:
        return "0"
    e = math.floor(math.log10(x))
    m = math.ceil(x / 10**e - 1e-9)
    if m == 10:
        m, e = 1, e + 1
    return f"{m}e{e}"


def documented() -> dict[str, str]:
    text = DOC.read_text(encoding="utf-8")
    if BEGIN not in text:
        return {}
    body = text.split(BEGIN, 1)[1].split(END, 1)[0]
    out = {}
    for line in body.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) == 5 and cells[0] not in ("id", "---"):
            out[cells[0].strip("`")] = cells[4]
    return out


@pytest.fixture
def agreement():
    """``agreement(id, metric, reference, version, input, measured)``: record a measured
    difference (absolute unless the metric says relative) and check it against docs/metrics.md."""

    def record(row_id: str, metric: str, reference: str, version: str, what: str, measured: float) -> None:
        measured = float(measured)
        assert math.isfinite(measured), f"{row_id}: non-finite difference"
        _ROWS[row_id] = (metric, f"{reference} ({version})", what, bound_text(measured))
        if os.environ.get("RECON_EVAL_WRITE_AGREEMENT"):
            return
        doc = documented()
        assert row_id in doc, f"{row_id} missing from the agreement table of {DOC} (regenerate it)"
        bound = float(doc[row_id])
        assert measured <= bound * (1 + 1e-9), f"{row_id}: measured {measured:.3g} > documented {doc[row_id]}"

    return record


def _table_lines(text: str) -> dict[str, str]:
    if BEGIN not in text:
        return {}
    body = text.split(BEGIN, 1)[1].split(END, 1)[0]
    out = {}
    for line in body.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) == 5 and cells[0] not in ("id", "---"):
            out[cells[0].strip("`")] = line
    return out


def pytest_sessionfinish(session, exitstatus):
    if not os.environ.get("RECON_EVAL_WRITE_AGREEMENT") or not _ROWS:
        return
    text = DOC.read_text(encoding="utf-8")
    lines = _table_lines(text)
    for k, (m, r, w, b) in _ROWS.items():
        lines[k] = f"| `{k}` | {m} | {r} | {w} | {b} |"
    block = f"{BEGIN}\n{HEADER}\n" + "\n".join(lines.values()) + f"\n{END}"
    if BEGIN in text:
        text = re.sub(re.escape(BEGIN) + ".*?" + re.escape(END), lambda _: block, text, flags=re.S)
    else:
        text = text.rstrip("\n") + "\n\n" + block + "\n"
    DOC.write_text(text, encoding="utf-8")
