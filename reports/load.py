"""Reading a campaign's output folder (what the harness wrote)."""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd


@dataclass(frozen=True)
class CampaignOutput:
    """The tables of one campaign run; optional ones are empty DataFrames when absent."""

    path: Path
    meta: dict
    results: pd.DataFrame
    scores: pd.DataFrame
    flights: pd.DataFrame = field(default_factory=pd.DataFrame)
    modes: pd.DataFrame = field(default_factory=pd.DataFrame)
    examples: pd.DataFrame = field(default_factory=pd.DataFrame)
    differentiation: pd.DataFrame = field(default_factory=pd.DataFrame)

    @property
    def truth_scores(self) -> pd.DataFrame:
        """Scores of parameters with a truth (bias terms left out)."""
        s = self.scores
        return s[s["truth"].notna()] if "truth" in s else s


def read_output(path: str | Path) -> CampaignOutput:
    """Read ``results.parquet``, ``scores.parquet``, ``run.json`` and the artifacts."""
    p = Path(path)
    missing = [f for f in ("results.parquet", "scores.parquet", "run.json") if not (p / f).is_file()]
    if missing:
        raise FileNotFoundError(f"{p} is not a campaign output folder: {', '.join(missing)} missing "
                                "(run `sidbench campaign FILE --out DIR` first)")

    def opt(name: str) -> pd.DataFrame:
        f = p / f"{name}.parquet"
        return pd.read_parquet(f) if f.is_file() else pd.DataFrame()
    return CampaignOutput(path=p, meta=json.loads((p / "run.json").read_text()),
                          results=pd.read_parquet(p / "results.parquet"), scores=pd.read_parquet(p / "scores.parquet"),
                          flights=opt("flights"), modes=opt("modes"), examples=opt("examples"),
                          differentiation=opt("differentiation"))


def provenance(meta: dict) -> dict:
    """The provenance block of a report from a run's metadata."""
    import datetime as dt
    c = meta.get("campaign", {})
    return {"campaign": c.get("name"), "file": c.get("file"), "sha256": c.get("sha256"),
            "commit": meta.get("commit"), "dirty": meta.get("dirty"), "versions": meta.get("versions", {}),
            "seed": meta.get("seed"), "executor": meta.get("executor"),
            "start": meta.get("start"), "end": meta.get("end"), "realizations": c.get("realizations"),
            "truth": c.get("truth"), "generated_at": dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds")}
