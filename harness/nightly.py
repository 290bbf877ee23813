"""The nightly accuracy run: the `nightly` campaign, its history, and the gates."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from harness.campaign import load_campaign
from harness.gates import DEFAULT_GATES, check_gates, load_gates
from harness.runner import CampaignRun, run_campaign
from harness.store import read_history, write_parquet
from harness.studies import differentiation_study


@dataclass(frozen=True)
class NightlyRun:
    run: CampaignRun
    gates: pd.DataFrame
    previous: dict | None
    history: list

    @property
    def passed(self) -> bool:
        return bool(self.gates.empty or self.gates["passed"].all())


def run_nightly(out_dir: str | Path, *, history_dir: str | Path, campaign: str = "nightly",
                gates_file: str | Path = DEFAULT_GATES, realizations: int | None = None,
                workers: int | None = None, scheduler: str | None = None, cache_dir: str | Path | None = None,
                progress: bool = True) -> NightlyRun:
    """Run the nightly campaign into ``out_dir`` (a fresh folder per night), compare it with
    the previous run in ``history_dir`` and with the declared gates, and append it to the
    history. The seed's Fig. 1 differentiation study is run too (``differentiation.parquet``)."""
    c = load_campaign(campaign)
    if realizations is not None:
        c = c.with_realizations(realizations)
    gates = load_gates(gates_file)
    past = read_history(Path(history_dir), c.name)
    previous = past[-1] if past else None
    run = run_campaign(c, out_dir, scheduler=scheduler, workers=workers, cache_dir=cache_dir,
                       history_dir=history_dir, progress=progress)
    write_parquet(differentiation_study(100, seed=c.seed), Path(out_dir) / "differentiation.parquet")
    table = check_gates(run.scores, gates, previous[1] if previous else None)
    write_parquet(table, Path(out_dir) / "gates.parquet")
    return NightlyRun(run, table, previous[0] if previous else None, read_history(Path(history_dir), c.name))
