"""What the plugin boundary costs: a plugin against the built-in backend it wraps, from runs of both.

    python3 scripts/plugin_boundary.py RUN.csv [RUN.csv ...] --plugin NAME --builtin NAME [--target 0.98] [--out FILE.md]

Each run traced both with the built-in as the reference (`raybench run --reference bvh8`), in
interleaved rounds, so every round gives one paired ratio plugin / built-in per scene and ray set.
Rounds cancel what changes over time (a busy neighbour) but not what one process fixes once: where
its trees and rays landed in memory moved single rows by up to 10 % between processes of the same
binaries. So the runs are independent processes, and the table pools them: for each scene and ray
set (one thread), both backends' median rates, the median of every run's paired ratios, and the
lowest and highest of the runs' own medians. The target (issue 30): the plugin traces within 2 %
of the built-in, a pooled median >= 0.98 on every row; geometric means are reported overall and
per ray set. A row below the target is said to be within the runs' spread (some run's median
reaching 1.0) or beyond it. Prints Markdown (or writes --out). Bad input: one line on stderr, exit 2.
"""
import argparse
import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from report import InputError, geometric_mean, ordered, rate_samples, read_meta, read_table  # noqa: E402

REQUIRED = ["scene", "rayset", "backend", "threads", "mrays_s", "mrays_s_samples"]
NUMERIC = ["threads", "mrays_s"]


def paired_rows(path, rows, plugin, builtin):
    """(scene, rayset, plugin row, built-in row, paired ratios) for every one-thread pair."""
    by_key = {(r["scene"], r["rayset"], r["backend"], r["threads"]): r for r in rows}
    out = []
    for scene in ordered(r["scene"] for r in rows):
        for rayset in ordered(r["rayset"] for r in rows if r["scene"] == scene):
            p = by_key.get((scene, rayset, plugin, 1))
            b = by_key.get((scene, rayset, builtin, 1))
            if not p or not b:
                continue
            ps, bs = rate_samples(path, p), rate_samples(path, b)
            if len(ps) != len(bs):
                raise InputError(path, f"{scene}/{rayset}: {len(ps)} plugin samples against {len(bs)} built-in ones;"
                                 " a paired comparison needs one of each per round")
            out.append((scene, rayset, p, b, [x / y for x, y in zip(ps, bs)]))
    if not out:
        raise InputError(path, f"no scene and ray set has one-thread rows of both {plugin} and {builtin}")
    return out


def report(paths, plugin, builtin, target):
    runs = []  # per run: {(scene, rayset): (plugin row, built-in row, ratios)}
    metas = []
    for path in paths:
        meta = read_meta(path)
        if meta.get("timing") != "rounds":
            raise InputError(path, "the run's samples are not paired by round (metadata timing = \"rounds\"); "
                             "run it again with this raybench")
        metas.append(meta)
        runs.append({(sc, rs): (p, b, ratios) for sc, rs, p, b, ratios in
                     paired_rows(path, read_table(path, REQUIRED, NUMERIC), plugin, builtin)})
    keys = [k for k in runs[0] if all(k in run for run in runs)]
    if not keys:
        raise InputError(paths[0], "no scene and ray set is in every run")
    meta = metas[0]
    lines = [f"# The plugin boundary: `{plugin}` against `{builtin}`", ""]
    lines.append(f"Machine: {meta.get('cpu', '?')} ({meta.get('cpu_id', '?')}); commit {meta.get('git_commit', '?')}; "
                 f"compiler {meta.get('compiler', '?')}; {len(runs)} run(s) of {meta.get('repetitions', '?')} rounds, "
                 "one thread.")
    for m in metas:
        lines.append(f"Command: `{m.get('command', '?')}`")
    lines.append("")
    lines.append(f"Target: the plugin's pooled median paired ratio >= {target:g} on every row.")
    lines.append("")
    lines.append("| scene | ray set | built-in Mrays/s | plugin Mrays/s | pooled paired ratio | runs' medians | target |")
    lines.append("|---|---|---:|---:|---:|---|---|")
    medians, below = [], []
    for scene, rayset in keys:
        pooled = [x for run in runs for x in run[(scene, rayset)][2]]
        per_run = [statistics.median(run[(scene, rayset)][2]) for run in runs]
        m = statistics.median(pooled)
        medians.append((rayset, m))
        b_rate = statistics.median(run[(scene, rayset)][1]["mrays_s"] for run in runs)
        p_rate = statistics.median(run[(scene, rayset)][0]["mrays_s"] for run in runs)
        if m >= target:
            verdict = "met"
        else:
            below.append(f"{scene}/{rayset}")
            verdict = "missed, within the runs' spread" if max(per_run) >= 1.0 else "missed"
        lines.append(f"| {scene} | {rayset} | {b_rate:.3f} | {p_rate:.3f} | {m:.3f} | "
                     f"{min(per_run):.3f}-{max(per_run):.3f} | {verdict} |")
    lines.append("")
    values = [m for _, m in medians]
    lines.append(f"Geometric mean of the pooled paired ratios: {geometric_mean(values):.3f} over {len(values)} rows; "
                 f"lowest {min(values):.3f}, highest {max(values):.3f}.")
    per_rayset = [f"{rs} {geometric_mean([m for r, m in medians if r == rs]):.3f}"
                  for rs in ordered(r for r, _ in medians)]
    lines.append(f"Per ray set: {', '.join(per_rayset)}.")
    lines.append("")
    lines.append("Verdict: " + ("every row meets the target." if not below else
                                f"{len(below)} row(s) below the target: {', '.join(below)}."))
    return "\n".join(lines) + "\n", not below


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("csv", nargs="+", help="results CSVs of independent runs")
    parser.add_argument("--plugin", required=True, help="backend name of the plugin, as in the CSV")
    parser.add_argument("--builtin", required=True, help="backend name of the built-in it wraps")
    parser.add_argument("--target", type=float, default=0.98, help="lowest median paired ratio (default 0.98)")
    parser.add_argument("--out", help="write the Markdown here instead of stdout")
    args = parser.parse_args(argv)
    try:
        text, _ = report(args.csv, args.plugin, args.builtin, args.target)
    except InputError as e:
        print(f"plugin-boundary: error: {e}", file=sys.stderr)
        return 2
    if args.out:
        with open(args.out, "w", encoding="utf-8") as f:
            f.write(text)
    else:
        sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
