"""What the plugin boundary costs: a plugin against the built-in backend it wraps, from one run.

    scripts/plugin-boundary-report RESULTS.csv --plugin NAME --builtin NAME [--target 0.98] [--out FILE.md]

The run traced both with the built-in as the reference (`raybench run --reference bvh8`), in
interleaved rounds, so every round gives one paired ratio plugin / built-in per scene and ray set.
For each scene and ray set (one thread), the table gives both medians and the median of the paired
ratios with their min and max over the rounds. The target (issue 30): the plugin traces within 2 %
of the built-in, i.e. a median paired ratio >= 0.98, on every row; the geometric mean is reported
too, overall and per ray set. A row below the target is said to be within or beyond the run's noise (its ratios' range
reaching 1.0 or not). Prints Markdown (or writes --out). Bad input: one line on stderr, exit 2.
"""
import argparse
import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from report import InputError, geometric_mean, ordered, read_meta, read_table  # noqa: E402

REQUIRED = ["scene", "rayset", "backend", "threads", "mrays_s", "mrays_s_samples"]
NUMERIC = ["threads", "mrays_s"]


def samples_of(path, row):
    try:
        values = [float(s) for s in row["mrays_s_samples"].split(";")]
    except ValueError:
        raise InputError(path, f"{row['scene']}/{row['rayset']}/{row['backend']}: unreadable mrays_s_samples")
    if not values or any(not v > 0 for v in values):
        raise InputError(path, f"{row['scene']}/{row['rayset']}/{row['backend']}: samples must be > 0")
    return values


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
            ps, bs = samples_of(path, p), samples_of(path, b)
            if len(ps) != len(bs):
                raise InputError(path, f"{scene}/{rayset}: {len(ps)} plugin samples against {len(bs)} built-in ones;"
                                 " a paired comparison needs one of each per round")
            out.append((scene, rayset, p, b, [x / y for x, y in zip(ps, bs)]))
    if not out:
        raise InputError(path, f"no scene and ray set has one-thread rows of both {plugin} and {builtin}")
    return out


def report(path, plugin, builtin, target):
    rows = read_table(path, REQUIRED, NUMERIC)
    meta = read_meta(path)
    if meta.get("timing") != "rounds":
        raise InputError(path, "the run's samples are not paired by round (metadata timing = \"rounds\"); "
                         "run it again with this raybench")
    pairs = paired_rows(path, rows, plugin, builtin)
    lines = [f"# The plugin boundary: `{plugin}` against `{builtin}`", ""]
    lines.append(f"Machine: {meta.get('cpu', '?')} ({meta.get('cpu_id', '?')}); commit {meta.get('git_commit', '?')}; "
                 f"compiler {meta.get('compiler', '?')}; {meta.get('repetitions', '?')} rounds, one thread.")
    lines.append(f"Command: `{meta.get('command', '?')}`")
    lines.append("")
    lines.append(f"Target: the plugin's median paired ratio >= {target:g} on every row.")
    lines.append("")
    lines.append("| scene | ray set | built-in Mrays/s | plugin Mrays/s | paired ratio (min-max) | target |")
    lines.append("|---|---|---:|---:|---|---|")
    medians, below = [], []
    for scene, rayset, p, b, ratios in pairs:
        m = statistics.median(ratios)
        medians.append(m)
        lo, hi = min(ratios), max(ratios)
        if m >= target:
            verdict = "met"
        else:
            below.append(f"{scene}/{rayset}")
            verdict = "missed, within noise" if hi >= 1.0 else "missed"
        lines.append(f"| {scene} | {rayset} | {b['mrays_s']:.3f} | {p['mrays_s']:.3f} | {m:.3f} ({lo:.3f}-{hi:.3f}) "
                     f"| {verdict} |")
    lines.append("")
    gm = geometric_mean(medians)
    lines.append(f"Geometric mean of the paired ratios: {gm:.3f} over {len(medians)} rows; "
                 f"lowest {min(medians):.3f}, highest {max(medians):.3f}.")
    per_rayset = []
    for rayset in ordered(rs for _, rs, _, _, _ in pairs):
        of_set = [statistics.median(ratios) for _, rs, _, _, ratios in pairs if rs == rayset]
        per_rayset.append(f"{rayset} {geometric_mean(of_set):.3f}")
    lines.append(f"Per ray set: {', '.join(per_rayset)}.")
    lines.append("")
    lines.append("Verdict: " + ("every row meets the target." if not below else
                                f"{len(below)} row(s) below the target: {', '.join(below)}."))
    return "\n".join(lines) + "\n", not below


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("csv")
    parser.add_argument("--plugin", required=True, help="backend name of the plugin, as in the CSV")
    parser.add_argument("--builtin", required=True, help="backend name of the built-in it wraps")
    parser.add_argument("--target", type=float, default=0.98, help="lowest median paired ratio (default 0.98)")
    parser.add_argument("--out", help="write the Markdown here instead of stdout")
    args = parser.parse_args(argv)
    try:
        text, _ = report(args.csv, args.plugin, args.builtin, args.target)
    except InputError as e:
        print(f"plugin-boundary-report: {e}", file=sys.stderr)
        return 2
    if args.out:
        with open(args.out, "w", encoding="utf-8") as f:
            f.write(text)
    else:
        sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
