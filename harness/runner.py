"""Running a campaign: resumable, on any executor, with identical numbers everywhere."""
from __future__ import annotations

import contextlib
import datetime as dt
import fcntl
import hashlib
import json
import os
import time
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from harness.atomic import ensure_folder, write_json_atomic
from harness.campaign import Campaign, CampaignError, Task
from harness.errors import Interrupted, OptionError
from harness.executors import make_executor
from harness.progress import Progress
from harness.scores import score
from harness.store import append_history, git_commit, versions, write_parquet, write_run
from harness.tasks import preflown, prefly, run_task

DEFAULT_CACHE = Path(".sidbench-cache")


@dataclass(frozen=True)
class CampaignRun:
    """What a run produced and how long it took."""

    results: pd.DataFrame
    scores: pd.DataFrame
    meta: dict
    out_dir: Path


def _task_path(out_dir: Path, task: Task) -> Path:
    return out_dir / "tasks" / f"{task.task_id}.parquet"


def _finished_tasks(out_dir: Path) -> list[Path]:
    tasks = out_dir / "tasks"
    return sorted(tasks.glob("*.parquet")) if tasks.is_dir() else []


def _check_out_dir(out_dir: Path, campaign: Campaign) -> None:
    """Refuse to mix two different campaigns' tasks in one folder. A folder without a finished
    task holds nothing to protect: its marker is simply replaced."""
    marker = out_dir / "campaign.json"
    ident = {"name": campaign.name, "sha256": campaign.text_hash}
    if marker.is_file() and _finished_tasks(out_dir):
        try:
            old = json.loads(marker.read_text())
        except (ValueError, UnicodeDecodeError):
            old = {}
        if old.get("sha256") != campaign.text_hash:
            raise CampaignError(f"{out_dir} holds results of campaign {old.get('name')!r} from a different campaign "
                                f"file (sha256 {str(old.get('sha256', ''))[:12]} vs {campaign.text_hash[:12]}); "
                                "use another --out folder or delete it")
    else:
        write_json_atomic(marker, ident)


def _remove_stale_temporaries(out_dir: Path) -> int:
    """Temporary files a killed run left in ``tasks/`` (this run holds the folder's lock)."""
    tasks = out_dir / "tasks"
    stale = list(tasks.glob(".*.tmp")) if tasks.is_dir() else []
    for p in stale:
        p.unlink(missing_ok=True)
    return len(stale)


@contextlib.contextmanager
def _folder_lock(out_dir: Path):
    """One run at a time per output folder (the lock goes with the process, even on kill -9)."""
    with open(out_dir / ".lock", "a+b") as fh:
        try:
            fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise CampaignError(f"{out_dir}: another sidbench campaign is running in this folder") from None
        yield


def _resume_hint(out_dir: Path) -> str:
    return (f"finished tasks are kept in {out_dir / 'tasks'}; run the same command again to resume "
            "where it stopped")


def run_campaign(campaign: Campaign, out_dir: str | Path, *, scheduler: str | None = None,
                 workers: int | None = None, cache_dir: str | Path | None = None,
                 history_dir: str | Path | None = None, progress: bool = True) -> CampaignRun:
    """Run every task of ``campaign`` not already finished in ``out_dir`` and score them all.

    Finished tasks are written to ``out_dir/tasks/<task id>.parquet`` as they complete (a
    temporary file, then a rename), so after an interruption the same command finishes the
    rest without recomputing anything, and the final tables are identical to an
    uninterrupted run's.
    """
    if workers is not None and workers < 1:
        raise OptionError(f"--workers must be at least 1, not {workers}")
    out_dir = ensure_folder(out_dir, "output folder")
    try:
        with _folder_lock(out_dir):
            return _run_locked(campaign, out_dir, scheduler=scheduler, workers=workers, cache_dir=cache_dir,
                               history_dir=history_dir, progress=progress)
    except KeyboardInterrupt:
        raise Interrupted(_resume_hint(out_dir)) from None


def _run_locked(campaign: Campaign, out_dir: Path, *, scheduler: str | None, workers: int | None,
                cache_dir: str | Path | None, history_dir: str | Path | None, progress: bool) -> CampaignRun:
    _check_out_dir(out_dir, campaign)
    _remove_stale_temporaries(out_dir)
    cache = str(Path(cache_dir) if cache_dir else DEFAULT_CACHE)
    workers = workers or max(1, os.cpu_count() or 1)
    tasks = campaign.tasks()
    pending = [t for t in tasks if not _task_path(out_dir, t).is_file()]
    start = dt.datetime.now(dt.timezone.utc)
    t0 = time.perf_counter()
    compute = 0.0
    with make_executor(scheduler, workers) as ex:
        keys = sorted({f for t in pending for f in preflown(t)}, key=lambda k: k.digest())
        missing = [k for k in keys if not (Path(cache) / "flights" / f"{k.digest()}.parquet").is_file()]
        bar = Progress(len(missing) + len(pending), f"{campaign.name}", enabled=progress)
        for _, seconds in ex.imap_unordered(prefly, missing, cache):
            compute += seconds
            bar.update()
        for task, (rows, seconds) in ex.imap_unordered(run_task, pending, cache):
            write_parquet(rows, _task_path(out_dir, task))
            compute += seconds
            bar.update()
        executor = ex.description
    wall = time.perf_counter() - t0
    results = collect(out_dir, tasks)
    scores = score(results, campaign.truth)
    end = dt.datetime.now(dt.timezone.utc)
    meta = {
        "run_id": f"{start:%Y%m%dT%H%M%S}-{campaign.name}-{hashlib.sha256(str(t0).encode()).hexdigest()[:6]}",
        "campaign": {"name": campaign.name, "file": campaign.path, "sha256": campaign.text_hash,
                     "description": campaign.description, "realizations": campaign.realizations,
                     "truth": campaign.truth, "cells": campaign.cell_count, "tasks": len(tasks)},
        "seed": campaign.seed, "seeds": "per task in results.seed, derived from the master seed and the task's identity",
        **git_commit(), "versions": versions(), "executor": executor, "workers": workers,
        "start": start.isoformat(), "end": end.isoformat(), "wall_s": wall,
        "tasks_run": len(pending), "tasks_resumed": len(tasks) - len(pending),
        "compute_s": compute,
        "harness_overhead": (1.0 - compute / (wall * min(workers, max(1, len(pending))))) if pending and wall > 0 else None,
        "estimates": int((~results["method"].isin(["crb", "excursion", "check"])).sum()),
    }
    write_run(out_dir, results, scores, meta)
    from harness.artifacts import write_artifacts
    write_artifacts(campaign, tasks, out_dir, cache)
    if history_dir is not None:
        append_history(Path(history_dir), scores, meta)
    return CampaignRun(results, scores, meta, out_dir)


def collect(out_dir: Path, tasks: list[Task]) -> pd.DataFrame:
    """All task rows in a fixed order (independent of completion order)."""
    frames = [pd.read_parquet(_task_path(out_dir, t)) for t in tasks]
    df = pd.concat(frames, ignore_index=True)
    order = ["campaign", "flight", "noise", "method", "errors", "equation", "parameter", "realization"]
    return df.sort_values(order, kind="stable").reset_index(drop=True)
