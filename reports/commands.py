"""Subcommands that write reports (registered in ``harness.cli``, the composition root)."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from reports.html import write_html
from reports.jsonreport import write_json
from reports.markdown import markdown_text, write_markdown
from harness.errors import OptionError


def write_all(report, out_dir: Path, stem: str = "report") -> Path:
    """HTML, Markdown and JSON side by side; returns the HTML path."""
    out_dir = Path(out_dir)
    html = write_html(report, out_dir / f"{stem}.html")
    write_markdown(report, out_dir / f"{stem}.md", html_name=html.name)
    write_json(report, out_dir / f"{stem}.json")
    return html


def cmd_report(args: argparse.Namespace) -> int:
    from reports.load import read_output
    outputs = [read_output(d) for d in args.dirs]
    if args.kind == "benchmark":
        from reports.benchmark_report import benchmark_report
        report = benchmark_report(outputs)
    else:
        if len(outputs) != 1:
            raise OptionError("a campaign report takes one folder; use --kind benchmark to compare several")
        from reports.campaign_report import campaign_report
        report = campaign_report(outputs[0])
    out = Path(args.out) if args.out else Path(args.dirs[0])
    html = write_all(report, out, args.kind if args.kind == "benchmark" else "report")
    print(markdown_text(report))
    print(f"\nwrote {html}, {html.with_suffix('.md')}, {html.with_suffix('.json')}")
    return 0


def cmd_nightly(args: argparse.Namespace) -> int:
    from harness.nightly import run_nightly
    from reports.load import read_output
    from reports.nightly_report import nightly_report
    night = run_nightly(args.out, history_dir=args.history or Path(args.out).parent / "history",
                        campaign=args.campaign, gates_file=args.gates, realizations=args.realizations,
                        workers=args.workers, scheduler=args.scheduler, cache_dir=args.cache, progress=not args.quiet)
    report = nightly_report(read_output(args.out), night.gates, night.history, night.previous, args.nights)
    html = write_all(report, Path(args.out), "nightly")
    print(markdown_text(report))
    print(f"\nwrote {html}")
    if not night.passed:
        failed = night.gates[~night.gates["passed"]]
        for _, r in failed.iterrows():
            print(f"GATE FAILED [{r['gate']}] {r['message']}", file=sys.stderr)
        return 1
    return 0


def cmd_review_maneuvers(args: argparse.Namespace) -> int:
    from harness.review import review_campaign, run_review
    from reports.load import read_output
    from reports.maneuver_review import maneuver_review
    kinds = tuple(k.strip() for k in args.maneuvers.split(",") if k.strip())
    axes = ("lon", "lat") if args.axis == "both" else (args.axis,)
    campaign = review_campaign(args.aircraft, args.condition, kinds, axes, args.noise, args.realizations)
    _, corr = run_review(campaign, args.out, workers=args.workers, scheduler=args.scheduler, cache_dir=args.cache,
                         progress=not args.quiet)
    report = maneuver_review(read_output(args.out), corr)
    html = write_all(report, Path(args.out), "review")
    print(markdown_text(report))
    print(f"\nwrote {html}")
    return 0


def cmd_diagnose(args: argparse.Namespace) -> int:
    """Run the discrepancy diagnosis and write its report."""
    from harness.diagnosis.run import diagnose
    from reports.diagnosis_report import write_diagnosis_report
    result = diagnose(args.model, args.recording, args.out, args.validation, mass=args.mass,
                      calibrate=getattr(args, "calibrate", True), calibrate_workers=getattr(args, "workers", 2),
                      aero_reference=getattr(args, "aero_reference", "auto"))
    html = write_diagnosis_report(Path(args.out), getattr(args, "workers", 2))
    for f in result["findings"]:
        if f["effect"] == "none":
            print(f"none: {f['explanation']}")
        else:
            print(f"{f['effect']}: {f['parameter']} = {f['estimate']:.4g} ± {f['std_error']:.2g} {f['units']}"
                  f"  (t = {f['evidence']['t']:.1f})")
            print(f"    {f['explanation']}")
    print(f"{result['located']['summary']}")
    cal = result.get("calibration") or {}
    if "hold" in cal:
        print(f"calibration in the loop {'used' if cal['used'] else 'not used'}: {cal['reason']}")
    print(f"diagnosis took {result['timing_s']['total']:.1f} s; wrote {Path(args.out) / 'findings.json'} and {html}")
    return 0


def cmd_demo(args: argparse.Namespace) -> int:
    """Fly the default maneuver and print its truth, then run a quick campaign and report it."""
    from harness.campaign import load_campaign
    from harness.flying import fly_default
    from harness.runner import run_campaign
    from harness.store import write_parquet
    from harness.studies import differentiation_study
    from reports.campaign_report import campaign_report
    from reports.load import read_output
    out = Path(args.out)
    fly_default(out)
    campaign = load_campaign("regressor-noise").with_realizations(args.realizations)
    print(f"\nRunning campaign {campaign.name} with {campaign.realizations} realizations ...", flush=True)
    run = run_campaign(campaign, out / "campaign", workers=args.workers, cache_dir=out / "cache", progress=True)
    write_parquet(differentiation_study(100, seed=campaign.seed), out / "campaign" / "differentiation.parquet")
    report = campaign_report(read_output(out / "campaign"))
    html = write_all(report, out)
    print(f"{run.meta['estimates']} estimates in {run.meta['wall_s']:.1f} s on {run.meta['executor']}.")
    print(f"\n{report.status.upper()} ({report.status_note})")
    for line in report.summary[1:-1]:  # the report's lead: what was flown (not the F-16 above) and what it found
        print(f"- {line}")
    print(f"\nReport: {html.resolve()}")
    return 0
