"""`python -m oit bench --claims`: the seeds' quantitative and comparative claims, each measured
on this engine with a verdict (docs/claims.md), one module a seed. The quick claims fit CI in
seconds (small frames, thinned scenes) and `tests/test_claims.py` checks that their verdicts
still read as docs/claims.md writes them; `--claims --full` adds the ones that need the scenes
at their size, or GPU times (minutes on lavapipe)."""

from __future__ import annotations

from ... import Renderer
from ..harness import Result
from . import adaptive, hybrid, kerzner, later, rtr
from .common import FAILS, HOLDS, NOT_HERE, Claim

__all__ = ["CLAIMS", "CLAIM_COLUMNS", "Claim", "FAILS", "HOLDS", "NOT_HERE", "run_claims"]

CLAIMS: list[Claim] = hybrid.CLAIMS + adaptive.CLAIMS + kerzner.CLAIMS + rtr.CLAIMS + later.CLAIMS

CLAIM_COLUMNS = [("id", "{}"), ("source", "{}"), ("claim", "{}"), ("measured", "{}"), ("verdict", "{}")]


def run_claims(full: bool = False, only: list[str] | None = None) -> Result:
    """Measures the claims named in `only`, or else the quick claims (and, with `full`, all of
    them); a claim whose measurement raises is a row that says so."""
    unknown = sorted(set(only or ()) - {c.id for c in CLAIMS})
    if unknown:
        raise ValueError(f"no claim {', '.join(unknown)}; the claims are {', '.join(c.id for c in CLAIMS)}")
    result = Result(rows=[])
    adapter = Renderer(1, 1).adapter_info["name"]
    for c in CLAIMS:
        if (c.id not in only) if only else not (c.quick or full):
            continue
        try:
            measured, verdict = c.measure()
        except (RuntimeError, MemoryError, ValueError) as e:
            measured, verdict = f"failed: {str(e).splitlines()[0]}", NOT_HERE
        result.rows.append({"id": c.id, "source": c.source, "claim": c.claim, "measured": measured, "verdict": verdict,
                            "quick": c.quick, "adapter": adapter, "status": "ok", "message": ""})
        print(f"{c.id}: {verdict}: {measured}", flush=True)
    return result

