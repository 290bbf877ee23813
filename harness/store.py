"""The results store: tidy results, scores and run metadata, written atomically; history."""
from __future__ import annotations

import importlib.metadata
import io
import json
import subprocess
from pathlib import Path

import pandas as pd

from harness.atomic import write_atomic, write_json_atomic

PACKAGES = ("jsbsim", "numpy", "scipy", "pandas", "pyarrow", "matplotlib", "dask", "distributed")
REPO = Path(__file__).resolve().parents[1]


def write_parquet(df: pd.DataFrame, path: Path) -> Path:
    """Write ``df`` to Parquet atomically."""
    def writer(fh):
        buf = io.BytesIO()
        df.to_parquet(buf, index=False)
        fh.write(buf.getvalue())
    return write_atomic(path, writer)


def git_commit() -> dict:
    """The checkout's commit and whether it has uncommitted changes."""
    try:
        sha = subprocess.run(["git", "rev-parse", "HEAD"], cwd=REPO, capture_output=True, text=True,
                             timeout=10).stdout.strip()
        dirty = bool(subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=REPO,
                                    capture_output=True, text=True, timeout=10).stdout.strip())
    except (OSError, subprocess.SubprocessError):
        sha, dirty = "", False
    return {"commit": sha or "unknown", "dirty": dirty}


def versions() -> dict:
    out = {}
    for p in PACKAGES:
        try:
            out[p] = importlib.metadata.version(p)
        except importlib.metadata.PackageNotFoundError:
            out[p] = None
    return out


def write_run(out_dir: Path, results: pd.DataFrame, scores: pd.DataFrame, meta: dict) -> None:
    """``results.parquet``, ``scores.parquet`` and ``run.json`` in ``out_dir``."""
    write_parquet(results, out_dir / "results.parquet")
    write_parquet(scores, out_dir / "scores.parquet")
    write_json_atomic(out_dir / "run.json", meta)


def append_history(history_dir: Path, scores: pd.DataFrame, meta: dict) -> Path:
    """Keep this run's scores and metadata under ``history_dir/<run id>/`` (append-only)."""
    run_dir = Path(history_dir) / meta["run_id"]
    write_parquet(scores, run_dir / "scores.parquet")
    write_json_atomic(run_dir / "run.json", meta)
    return run_dir


def read_history(history_dir: Path, campaign: str | None = None) -> list[tuple[dict, pd.DataFrame]]:
    """All stored runs (oldest first), optionally of one campaign."""
    runs = []
    for run_json in sorted(Path(history_dir).glob("*/run.json")):
        meta = json.loads(run_json.read_text())
        if campaign is None or meta.get("campaign", {}).get("name") == campaign:
            runs.append((meta, pd.read_parquet(run_json.parent / "scores.parquet")))
    runs.sort(key=lambda r: r[0].get("start", ""))
    return runs
