"""Issue 4's scorecard: how our BVHs stand against Embree's best, per scene, from one results CSV.

    scripts/bvh-scorecard RESULTS.csv [--out SCORECARD.md] [--plot PICTURE.png | --no-plot]

For every scene and the primary, diffuse and shadow ray sets (one thread), it compares:
- our best backend (every backend not named embree* or reference) with Embree's best (the faster
  of `embree` and `embree:high`, when the run has both): target >= 1.0 per scene and ray set,
  and >= 1.10 as a geometric mean;
- our best watertight configuration (a backend name with the option "watertight" and not
  "plain_boxes", the leaky combination: see is_watertight) with Embree's default mode (`embree`):
  target >= 1.0;
- the build time of the default builder (`bvh8`, else `bvh2`) with Embree's medium build
  (`embree`): target <= 1.0;
- hit/miss agreement with Embree (>= 99.99 %) and same triangle where both hit, ties counted as
  agreeing (>= 99.9 %), for every one of our backends in the run (the table's columns give our
  best backend's; the target line names the worst row and backend).
Ratios are within the run, so they travel between machines; the run's metadata names the
machine. When the CSV has each median's min and max over the repetitions, every ratio gets its
range too (ours at its slowest / Embree at its fastest, and the reverse), and a ratio below a
target is said to be within that noise or beyond it; the verdict stays the median's. Build times
likewise, from their min and max over the timing rounds (a build ratio above 1.0, or a build no
faster with more threads, is said to be within their range or beyond it). How noisy the run was
is said from Embree's own rates: their spread over the repetitions, (max - min) / median, per row.
Prints Markdown (or writes --out). With --out, a picture of the ratios (PNG beside it, or
--plot) is drawn and linked from the Markdown. Bad input: one line on stderr, exit 2.
"""
import argparse
import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from report import (DPI, InputError, draw_grouped_bars, figure_width, geometric_mean, pyplot, read_meta,  # noqa: E402
                    read_table, rotate_if_crowded, wrap_title)

RAYSETS = ("primary", "diffuse", "shadow")
REQUIRED = ["scene", "rayset", "backend", "threads", "rays", "mrays_s", "build_ms", "hit_rate", "agree_hit",
            "agree_prim", "prim_ties"]
NUMERIC = ["threads", "rays", "mrays_s", "build_ms", "hit_rate", "agree_hit", "agree_prim", "prim_ties", "mrays_s_min",
           "mrays_s_max", "build_ms_min", "build_ms_max"]


def is_watertight(backend):
    """A leak-free configuration: the watertight triangle test, traversed with the conservative box
    test. Since issue 28 that is every name with the option "watertight" except those that add
    "plain_boxes" (the plain box test leaks at shared vertices and edges). Runs before the rename
    (results/README.md) called the leaky combination plain "bvh8:watertight"."""
    options = backend.split(":")[1:]
    return "watertight" in options and "plain_boxes" not in options


def is_ours(backend):
    return not backend.startswith("embree") and backend != "reference"


def same_triangle(row):
    """Where both hit: same triangle, or another at exactly the same t (a tie is not an error)."""
    if row["agree_prim"] is None or not row["hit_rate"] or not row["rays"]:
        return None
    both = row["hit_rate"] * row["rays"]
    return min(1.0, row["agree_prim"] + (row["prim_ties"] or 0) / both) if both else None


def ratio_range(ours, theirs, column="mrays_s"):
    """(lowest, highest) of ours / theirs in `column` over the repetitions (mrays_s, or build_ms
    over the timed builds): ours at its min against theirs at its max, and the reverse; None
    without the column's min and max."""
    lo, hi = ours.get(column + "_min"), ours.get(column + "_max")
    their_lo, their_hi = theirs.get(column + "_min"), theirs.get(column + "_max")
    if None in (lo, hi, their_lo, their_hi) or not their_lo or not their_hi:
        return None
    return lo / their_hi, hi / their_lo


def one_per_scene(lines):
    """The lines with a build ratio, one per scene: the rows of its ray sets share its build."""
    return list({x["scene"]: x for x in lines if x["build_ratio"] is not None}.values())


def scorecard(rows, threads=1):
    """Per (scene, rayset), at one thread count: the numbers of the table."""
    by = {}
    for r in rows:
        if r["threads"] == threads and r["rayset"] in RAYSETS and r["mrays_s"]:
            by.setdefault((r["scene"], r["rayset"]), {})[r["backend"]] = r
    lines = []
    for (scene, rayset), backends in by.items():
        embrees = {b: r for b, r in backends.items() if b in ("embree", "embree:high")}
        ours = {b: r for b, r in backends.items() if is_ours(b)}
        if not embrees or not ours:
            continue
        embree_name, embree = max(embrees.items(), key=lambda kv: kv[1]["mrays_s"])
        best_name, best = max(ours.items(), key=lambda kv: kv[1]["mrays_s"])
        watertight = {b: r for b, r in ours.items() if is_watertight(b)}
        wt_name, wt = max(watertight.items(), key=lambda kv: kv[1]["mrays_s"]) if watertight else (None, None)
        default = backends.get("embree")
        builder = ours.get("bvh8") or ours.get("bvh2")
        lines.append({
            "scene": scene, "rayset": rayset,
            "embree": embree_name, "embree_mrays": embree["mrays_s"],
            "best": best_name, "best_mrays": best["mrays_s"], "ratio": best["mrays_s"] / embree["mrays_s"],
            "ratio_range": ratio_range(best, embree),
            "watertight": wt_name,
            "watertight_ratio": wt["mrays_s"] / default["mrays_s"] if wt and default else None,
            "watertight_range": ratio_range(wt, default) if wt and default else None,
            "build_ratio": builder["build_ms"] / default["build_ms"] if builder and default and default["build_ms"] else None,
            "build_range": ratio_range(builder, default, "build_ms") if builder and default else None,
            **{k: builder.get(k) if builder else None for k in ("build_ms", "build_ms_min", "build_ms_max")},
            "agree_hit": best["agree_hit"], "same_triangle": same_triangle(best),
            "worst_agree_hit": min(((r["agree_hit"], b) for b, r in ours.items() if r["agree_hit"] is not None),
                                   default=None),
            "worst_same_triangle": min(((same_triangle(r), b) for b, r in ours.items() if same_triangle(r) is not None),
                                       default=None),
            "each": {b: r["mrays_s"] / embree["mrays_s"] for b, r in ours.items()},
        })
    return lines


# Embree's rates spreading more than this over their repetitions make a row noisy.
NOISY_SPREAD = 0.10


def run_noise(rows, threads=1):
    """One sentence on how noisy the run was, from Embree's own rows at `threads` (the same code every
    run, so their spread is the machine's): the median spread over the repetitions, the widest, and
    how many rows spread more than NOISY_SPREAD. None without the min and max columns."""
    spreads = sorted(((r["mrays_s_max"] - r["mrays_s_min"]) / r["mrays_s"], r["scene"], r["rayset"], r["backend"])
                     for r in rows if r["backend"] in ("embree", "embree:high") and r["threads"] == threads
                     and r["rayset"] in RAYSETS and r["mrays_s"] and r.get("mrays_s_min") is not None
                     and r.get("mrays_s_max") is not None)
    if not spreads:
        return None
    median = statistics.median(x[0] for x in spreads)
    widest, scene, rayset, backend = spreads[-1]
    noisy = sum(1 for x in spreads if x[0] > NOISY_SPREAD)
    return (f"Run noise: Embree's own rates spread over their repetitions by {100 * median:.0f} % (median over its "
            f"{len(spreads)} rows), at most {100 * widest:.0f} % ({scene} {rayset}, {backend}); {noisy} of "
            f"{len(spreads)} rows spread more than {100 * NOISY_SPREAD:.0f} %.")


def verdict(ok):
    return "**met**" if ok else "**missed**"


def render_threads(rows, lines):
    """With more threads (rows with threads > 1): our best / Embree's best per ray set, and the default
    build against Embree's medium build and against our own single-thread build."""
    counts = sorted({r["threads"] for r in rows if r["threads"] and r["threads"] > 1})
    out = []
    one = {(x["scene"], x["rayset"]): x for x in lines}
    for t in counts:
        many = scorecard(rows, t)
        if not many:
            continue
        out += ["", f"## With {t:g} threads", "",
                "TBB threads trace the same chunks of rays for Embree and ours; Embree builds with the same thread count.",
                "", f"| scene | ray set | our best | ratio, {t:g} threads | ratio, 1 thread | build / embree, {t:g} threads "
                "| our build, 1 → {:g} threads |".format(t), "|---|---|---|---:|---:|---:|---:|"]
        speedups = []  # one per scene (its ray sets share the build), with its range over the timed builds
        for x in many:
            base = one.get((x["scene"], x["rayset"]))
            speedup = base["build_ms"] / x["build_ms"] if base and base.get("build_ms") and x["build_ms"] else None
            if speedup and x["rayset"] == RAYSETS[0]:
                speedups.append({"speedup": speedup, "speedup_range": ratio_range(base, x, "build_ms")})
            out.append(f"| {x['scene']} | {x['rayset']} | {x['best']} | {x['ratio']:.2f} | "
                       f"{'-' if not base else format(base['ratio'], '.2f')} | "
                       f"{'-' if x['build_ratio'] is None else format(x['build_ratio'], '.2f')} | "
                       f"{'-' if speedup is None else format(speedup, '.2f') + '×'} |")
        ratios = [x["ratio"] for x in many]
        build_lines = one_per_scene(many)
        builds = [x["build_ratio"] for x in build_lines]
        out += ["", f"Geometric mean of our best / Embree's best with {t:g} threads: {geometric_mean(ratios):.2f}."]
        if builds:
            out.append(f"Default build with {t:g} threads / Embree medium with {t:g} threads: max {max(builds):.2f} "
                       f"({verdict(max(builds) <= 1.0)} ≤ 1.0"
                       f"{shortfall(build_lines, 'build_ratio', 'build_range', above=True, unit='scenes')}).")
        if speedups:
            fastest = [x["speedup"] for x in speedups]
            out.append(f"Our default build, 1 → {t:g} threads: {min(fastest):.2f}–{max(fastest):.2f}× faster "
                       f"({verdict(min(fastest) > 1.0)}: faster on every scene"
                       f"{shortfall(speedups, 'speedup', 'speedup_range', unit='scenes')}).")
    return out


def shortfall(lines, key, range_key, above=False, unit="rows"):
    """How many rows miss 1.0, and of those how many reach it within their repetitions' range:
    "; 3 of 36 rows below 1.0, 2 of them within their min–max", or "" when none miss. With
    `above`, the target is at most 1.0 (a build time ratio) and misses are above it."""
    measured = [x for x in lines if x[key] is not None]
    missed = [x for x in measured if (x[key] > 1.0 if above else x[key] < 1.0)]
    if not missed:
        return ""
    text = f"; {len(missed)} of {len(measured)} {unit} {'above' if above else 'below'} 1.0"
    if all(x[range_key] for x in missed):
        within = sum(1 for x in missed if (x[range_key][0] <= 1.0 if above else x[range_key][1] >= 1.0))
        text += f", {within} of them within their min–max"
    return text


def render_each(lines):
    """Each of our backends held to every row, against Embree's best: the best-of-several per row
    favours us when rates are noisy (the largest of six noisy rates is biased up more than the
    larger of two), so this says what a single choice of backend would give."""
    names = [b for b in dict.fromkeys(b for x in lines for b in x["each"]) if all(b in x["each"] for x in lines)]
    if len(names) < 2:
        return []
    out = ["", "Each of ours alone against Embree's best (geometric means; no pick per row):", "",
           "| backend | " + " | ".join(RAYSETS) + " | all | rows ≥ 1.0 |", "|---|" + "---:|" * (len(RAYSETS) + 2)]
    for b in names:
        per = [geometric_mean([x["each"][b] for x in lines if x["rayset"] == rs]) for rs in RAYSETS]
        ratios = [x["each"][b] for x in lines]
        out.append(f"| {b} | " + " | ".join("-" if v is None else f"{v:.2f}" for v in per) +
                   f" | {geometric_mean(ratios):.2f} | {sum(r >= 1.0 for r in ratios)} of {len(ratios)} |")
    return out


def plot_scorecard(path, lines, title):
    """Two panels of bars grouped by scene, one bar per ray set: our best / Embree's best, and our
    best watertight / Embree's default mode; whiskers min–max, the target 1.0 dashed."""
    plt = pyplot()
    scenes = list(dict.fromkeys(x["scene"] for x in lines))
    by = {(x["scene"], x["rayset"]): x for x in lines}
    colors = dict(zip(RAYSETS, ("tab:blue", "tab:orange", "tab:green")))
    panels = [("ratio", "ratio_range", "our best / Embree's best"),
              ("watertight_ratio", "watertight_range", "our watertight / Embree's default")]
    panels = [p for p in panels if any(x[p[0]] is not None for x in lines)]
    groups = scenes + ["geo. mean"]
    fig, axes = plt.subplots(len(panels), 1, figsize=(figure_width(groups, len(RAYSETS)), 3.6 * len(panels)),
                             layout="constrained", squeeze=False)
    for ax, (key, range_key, label) in zip(axes[:, 0], panels):
        means = {rs: geometric_mean([x[key] for x in lines if x["rayset"] == rs]) for rs in RAYSETS}

        def value_of(scene, rayset):
            if scene == "geo. mean":
                return None if means[rayset] is None else (means[rayset], None, None)
            x = by.get((scene, rayset))
            if x is None or x[key] is None:
                return None
            span = x[range_key]
            return (x[key], span[0], span[1]) if span else (x[key], None, None)
        draw_grouped_bars(ax, groups, RAYSETS, colors, value_of)
        ax.axhline(1.0, color="black", linewidth=1.2, linestyle="--", zorder=4, label="target (= 1.0)")
        ax.axvline(len(scenes) - 0.5, color="grey", linewidth=0.8, zorder=1)
        values = [v for x in lines for v in (x[key], *(x[range_key] or ())) if v is not None]
        ax.set_ylim(0, max(values + [1.0]) * 1.1)
        ax.set_ylabel(label + " (×)")
        ax.set_xticklabels(groups)
        rotate_if_crowded(ax, fig, groups)
        ax.legend(title="ray set (whisker: min–max)", loc="upper left", bbox_to_anchor=(1.0, 1.0), frameon=False)
    axes[0, 0].set_title(wrap_title(title, fig))
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def render(lines, meta, source, rows=(), plot=None):
    out = [f"# BVH scorecard: ours against Embree (issue 4)", "",
           f"From `{os.path.basename(source)}`, one thread, ratios within the run."]
    m = meta.get("machine", {}) if isinstance(meta.get("machine"), dict) else {}
    machine = m or meta
    facts = [f"{k}: {machine[k]}" for k in ("cpu", "cpu_id", "cpu_model", "host", "compiler", "embree", "embree_version", "git_commit",
                                             "commit") if k in machine]
    if facts:
        out += ["", "Machine and build: " + "; ".join(str(f) for f in facts) + "."]
    out += ["", "| scene | ray set | Embree's best | Mrays/s | our best | Mrays/s | ratio | watertight / embree "
            "| build / embree | agree hit | same tri |", "|---|---|---|---:|---|---:|---:|---:|---:|---:|---:|"]
    def fmt(v, f, unit=""):
        return "-" if v is None else format(v, f) + unit

    def with_range(v, span):
        return fmt(v, ".2f") + ("" if v is None or span is None else f" ({span[0]:.2f}–{span[1]:.2f})")
    for x in lines:
        out.append(f"| {x['scene']} | {x['rayset']} | {x['embree']} | {x['embree_mrays']:.2f} | {x['best']} | "
                   f"{x['best_mrays']:.2f} | {with_range(x['ratio'], x['ratio_range'])} | "
                   f"{with_range(x['watertight_ratio'], x['watertight_range'])} | "
                   f"{with_range(x['build_ratio'], x['build_range'])} | {fmt(None if x['agree_hit'] is None else 100 * x['agree_hit'], '.3f', ' %')} | "
                   f"{fmt(None if x['same_triangle'] is None else 100 * x['same_triangle'], '.2f', ' %')} |")
    if any(x["ratio_range"] for x in lines):
        out += ["", "A ratio's range in brackets: ours at its slowest over the repetitions against Embree at its fastest, "
                "and the reverse; for build times, our fastest build against Embree's slowest, and the reverse."]
    noise = run_noise(rows)
    if noise:
        out += ["", noise]
    ratios = [x["ratio"] for x in lines]
    per_rayset = {rs: geometric_mean([x["ratio"] for x in lines if x["rayset"] == rs]) for rs in RAYSETS}
    overall = geometric_mean(ratios)
    wts = [x["watertight_ratio"] for x in lines if x["watertight_ratio"] is not None]
    build_lines = one_per_scene(lines)
    builds = [x["build_ratio"] for x in build_lines]
    out += ["", "Geometric mean of our best / Embree's best: " +
            ", ".join(f"{rs} {v:.2f}" for rs, v in per_rayset.items() if v) + (f"; all {overall:.2f}." if overall else "."),
            "", "| target | measured | |", "|---|---|---|"]
    if ratios:
        out.append(f"| our best ≥ 1.0 × Embree's best on every scene and ray set | min {min(ratios):.2f}"
                   f"{shortfall(lines, 'ratio', 'ratio_range')} | {verdict(min(ratios) >= 1.0)} |")
        out.append(f"| geometric mean ≥ 1.10 | {overall:.2f} | {verdict(overall >= 1.10)} |")
    if wts:
        out.append(f"| watertight ≥ 1.0 × Embree's default mode | min {min(wts):.2f}"
                   f"{shortfall(lines, 'watertight_ratio', 'watertight_range')} | {verdict(min(wts) >= 1.0)} |")
    if builds:
        out.append(f"| default build ≤ 1.0 × Embree medium | max {max(builds):.2f}"
                   f"{shortfall(build_lines, 'build_ratio', 'build_range', above=True, unit='scenes')} | "
                   f"{verdict(max(builds) <= 1.0)} |")
    def worst(key):
        """The lowest (value, backend, scene, rayset) of `key` over every backend of ours, or None."""
        found = [(x[key][0], x[key][1], x["scene"], x["rayset"]) for x in lines if x[key] is not None]
        return min(found) if found else None
    agree, same = worst("worst_agree_hit"), worst("worst_same_triangle")
    if agree:
        out.append(f"| hit/miss agreement ≥ 99.99 %, every backend of ours | min {100 * agree[0]:.3f} % "
                   f"({agree[1]}, {agree[2]} {agree[3]}) | {verdict(agree[0] >= 0.9999)} |")
    if same:
        out.append(f"| same triangle ≥ 99.9 % (ties agree), every backend of ours | min {100 * same[0]:.2f} % "
                   f"({same[1]}, {same[2]} {same[3]}) | {verdict(same[0] >= 0.999)} |")
    out += render_each(lines)
    if plot:
        out += ["", f"![Our best and our best watertight backend against Embree, per scene and ray set]({plot})"]
    out += render_threads(rows, lines)
    return "\n".join(out) + "\n"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("results", help="results CSV of a run with embree (and embree:high) beside our backends")
    parser.add_argument("--out", help="write the Markdown here instead of stdout")
    parser.add_argument("--plot", help="the picture of the ratios (PNG; default: beside --out, same name; none without --out)")
    parser.add_argument("--no-plot", action="store_true", help="draw no picture")
    args = parser.parse_args(argv)
    plot = None if args.no_plot else args.plot or (os.path.splitext(args.out)[0] + ".png" if args.out else None)
    try:
        rows = read_table(args.results, REQUIRED, NUMERIC)
        lines = scorecard(rows)
        if not lines:
            raise InputError(args.results, "no single-thread primary, diffuse or shadow rows with both Embree and one of our backends")
        link = None
        if plot:
            plot_scorecard(plot, lines, "Issue 4: our BVHs against Embree, one thread, same rays, same run")
            # Linked from the Markdown relative to where it is written.
            link = os.path.relpath(plot, os.path.dirname(os.path.abspath(args.out))) if args.out else plot
        text = render(lines, read_meta(args.results), args.results, rows, link)
    except InputError as e:
        print(f"bvh-scorecard: error: {e}", file=sys.stderr)
        return 2
    except OSError as e:
        print(f"bvh-scorecard: error: {e.filename or plot}: {e.strerror or e}", file=sys.stderr)
        return 2
    if args.out:
        with open(args.out, "w") as f:
            f.write(text)
    else:
        sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
