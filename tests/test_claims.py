"""docs/claims.md cannot drift from the code: every claim `oit.bench.claims` measures has a
row there, and the quick ones (small frames, seconds) still give the verdict the row states."""

from __future__ import annotations

import os
import re

import pytest

from oit.bench.claims import CLAIMS, run_claims

DOC = os.path.join(os.path.dirname(__file__), "..", "docs", "claims.md")


def documented_verdicts() -> dict[str, str]:
    """Claim id -> verdict, from the rows of docs/claims.md's tables (`| id | ... | verdict |`)."""
    rows = {}
    with open(DOC) as f:
        for line in f:
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            verdict = re.search(r"\*\*(.+?)\*\*", cells[-1])
            if len(cells) >= 3 and re.fullmatch(r"[A-Z]+-[\w-]+", cells[0]) and verdict:
                rows[cells[0]] = verdict.group(1)
    return rows


def test_every_measured_claim_has_a_row():
    rows = documented_verdicts()
    missing = [c.id for c in CLAIMS if c.id not in rows]
    assert not missing, f"docs/claims.md has no row for {missing}"


def test_quick_claims_still_read_as_written():
    rows = documented_verdicts()
    result = run_claims(full=False)
    assert {r["id"] for r in result.rows} == {c.id for c in CLAIMS if c.quick}
    for r in result.rows:
        assert re.search(r"\d", r["measured"]), r  # a measurement, not a word
        assert r["verdict"] == rows[r["id"]], (r["id"], r["measured"], rows[r["id"]])


def test_unknown_claim_is_named():
    with pytest.raises(ValueError, match="no claim XX-none"):
        run_claims(only=["XX-none"])
