"""The scorecard of our BVHs against Embree, per scene and per machine class, from one results CSV.

    scripts/bvh-scorecard RESULTS.csv [--targets issue33|issue4|issue32|issue33,issue4]
                          [--out SCORECARD.md | --machine-dir DIR] [--plot PICTURE.png | --no-plot]
    scripts/bvh-scorecard --run [--dry-run] [--machine-dir DIR] [--backend LIST] [-- RAYBENCH OPTIONS]
    scripts/bvh-scorecard --index DIR

Issue 33's targets (the default), the machine class, the index of every class and --run's
command: machine_scorecard.py. This file: the command line, and issue 4's targets (--targets
issue4, which reproduces the scorecards made before issue 33). --targets issue32: the coherent
scorecard (machine_scorecard.render_coherent_card) of a run of meshes/coherent.toml. For every scene and the primary, diffuse and shadow ray sets (one thread), it compares:
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
machine. In a run timed in rounds (metadata timing = "rounds") a ratio is the median of the
per-round ratios, as raybench's own ratio_to_embree (docs/method.md), and its range their lowest
and highest; in an older run, the ratio of the medians, and with each median's min and max over
the repetitions its range (ours at its slowest / Embree at its fastest, and the reverse). A ratio
below a target is said to be within that noise or beyond it; the verdict stays the median's. Build times
likewise, from their min and max over the timing rounds (a build ratio above 1.0, or a build no
faster with more threads, is said to be within their range or beyond it). How noisy the run was
is said from Embree's own rates: their spread over the repetitions, (max - min) / median, per row.
Prints Markdown (or writes --out). With --out, a picture of the ratios (PNG beside it, or
--plot) is drawn and linked from the Markdown. Bad input: one line on stderr, exit 2.
"""
import argparse
import os
import shlex
import statistics
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from report import (DPI, InputError, draw_grouped_bars, figure_width, geometric_mean, pyplot, rate_samples,  # noqa: E402
                    read_meta, read_table, rotate_if_crowded, wrap_title)

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


def attach_round_samples(rows, meta, source):
    """Gives every row its rate samples in round order (`samples`, report.rate_samples) when the
    run pairs them by round (metadata timing = "rounds": sample i of every row of a scene is from
    round i, docs/method.md); rows of other runs keep none. Returns rows."""
    if (meta or {}).get("timing") != "rounds":
        return rows
    for r in rows:
        if r.get("mrays_s_samples"):
            r["samples"] = rate_samples(source, r)
    return rows


def paired_ratios(ours, theirs):
    """ours / theirs round by round (sample i over sample i), or None unless both rows carry samples
    from the same rounds (attach_round_samples)."""
    a, b = ours.get("samples"), theirs.get("samples")
    if not a or not b or len(a) != len(b):
        return None
    return [x / y for x, y in zip(a, b)]


def ratio_with_range(ours, theirs):
    """(ours / theirs, its (lowest, highest)), as docs/method.md defines a ratio: in a run paired by
    round, the median of the per-round ratios and their extremes, so that noise hitting a whole
    round cancels; otherwise the ratio of the medians and ratio_range (None without min and max).
    (None, None) without either row or with no rate of theirs."""
    if ours is None or theirs is None or not theirs["mrays_s"]:
        return None, None
    paired = paired_ratios(ours, theirs)
    if paired:
        return statistics.median(paired), (min(paired), max(paired))
    return ours["mrays_s"] / theirs["mrays_s"], ratio_range(ours, theirs)


def range_sentence(rows, theirs="Embree"):
    """What a ratio and its range in brackets are in this run's scorecard; `theirs`: what ours is
    compared with."""
    if any(r.get("samples") for r in rows):
        return (f"A ratio is the median over the timing rounds of ours / {theirs} in the same round (docs/method.md), "
                "its range in brackets the lowest and highest of those per-round ratios")
    return (f"A ratio's range in brackets: ours at its slowest over the repetitions against {theirs} at its fastest, "
            "and the reverse")


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
        ratio, ratio_span = ratio_with_range(best, embree)
        wt_ratio, wt_span = ratio_with_range(wt, default)
        lines.append({
            "scene": scene, "rayset": rayset,
            "embree": embree_name, "embree_mrays": embree["mrays_s"],
            "best": best_name, "best_mrays": best["mrays_s"], "ratio": ratio, "ratio_range": ratio_span,
            "watertight": wt_name, "watertight_ratio": wt_ratio, "watertight_range": wt_span,
            "build_ratio": builder["build_ms"] / default["build_ms"] if builder and default and default["build_ms"] else None,
            "build_range": ratio_range(builder, default, "build_ms") if builder and default else None,
            **{k: builder.get(k) if builder else None for k in ("build_ms", "build_ms_min", "build_ms_max")},
            "agree_hit": best["agree_hit"], "same_triangle": same_triangle(best),
            "worst_agree_hit": min(((r["agree_hit"], b) for b, r in ours.items() if r["agree_hit"] is not None),
                                   default=None),
            "worst_same_triangle": min(((same_triangle(r), b) for b, r in ours.items() if same_triangle(r) is not None),
                                       default=None),
            "each": {b: ratio_with_range(r, embree)[0] for b, r in ours.items()},
        })
    return lines


# Embree's rates spreading more than this over their repetitions make a row noisy.
NOISY_SPREAD = 0.10


def run_noise(rows, threads=1, kinds=RAYSETS):
    """One sentence on how noisy the run was, from Embree's own rows at `threads` (the same code every
    run, so their spread is the machine's): the median spread over the repetitions, the widest, and
    how many rows spread more than NOISY_SPREAD. None without the min and max columns."""
    spreads = sorted(((r["mrays_s_max"] - r["mrays_s_min"]) / r["mrays_s"], r["scene"], r["rayset"], r["backend"])
                     for r in rows if r["backend"] in ("embree", "embree:high") and r["threads"] == threads
                     and r["rayset"] in kinds and r["mrays_s"] and r.get("mrays_s_min") is not None
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


ISSUE4_PANELS = (("ratio", "ratio_range", "our best / Embree's best", 1.0),
                 ("watertight_ratio", "watertight_range", "our watertight / Embree's default", 1.0))


def plot_scorecard(path, lines, title, panels=ISSUE4_PANELS, kinds=RAYSETS):
    """Panels of bars grouped by scene, one bar per ray kind: by default our best / Embree's best, and
    our best watertight / Embree's default mode; whiskers min-max, each panel's target dashed."""
    plt = pyplot()
    scenes = list(dict.fromkeys(x["scene"] for x in lines))
    by = {(x["scene"], x["rayset"]): x for x in lines}
    kinds = [k for k in kinds if any(x["rayset"] == k for x in lines)]
    colors = dict(zip(kinds, ("tab:blue", "tab:orange", "tab:green", "tab:purple")))
    panels = [p for p in panels if any(x[p[0]] is not None for x in lines)]
    groups = scenes + ["geo. mean"]
    fig, axes = plt.subplots(len(panels), 1, figsize=(figure_width(groups, len(kinds)), 3.6 * len(panels)),
                             layout="constrained", squeeze=False)
    for ax, (key, range_key, label, target) in zip(axes[:, 0], panels):
        # The ray kinds this panel has ratios of (the coherent card's panels each have two).
        panel_kinds = [k for k in kinds if any(x["rayset"] == k and x[key] is not None for x in lines)]
        means = {rs: geometric_mean([x[key] for x in lines if x["rayset"] == rs]) for rs in panel_kinds}

        def value_of(scene, rayset):
            if scene == "geo. mean":
                return None if means[rayset] is None else (means[rayset], None, None)
            x = by.get((scene, rayset))
            if x is None or x[key] is None:
                return None
            span = x[range_key]
            return (x[key], span[0], span[1]) if span else (x[key], None, None)
        draw_grouped_bars(ax, groups, panel_kinds, colors, value_of)
        ax.axhline(target, color="black", linewidth=1.2, linestyle="--", zorder=4, label=f"target (= {target:g})")
        ax.axvline(len(scenes) - 0.5, color="grey", linewidth=0.8, zorder=1)
        values = [v for x in lines for v in (x[key], *(x[range_key] or ())) if v is not None]
        ax.set_ylim(0, max(values + [target]) * 1.1)
        ax.set_ylabel(label + " (×)")
        ax.set_xticklabels(groups)
        rotate_if_crowded(ax, fig, groups)
        ax.legend(title="ray kind (whisker: min–max)", loc="upper left", bbox_to_anchor=(1.0, 1.0), frameon=False)
    axes[0, 0].set_title(wrap_title(title, fig))
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def issue4_targets(lines):
    """Issue 4's targets on the single-thread lines: the geometric means and the target table."""
    ratios = [x["ratio"] for x in lines]
    per_rayset = {rs: geometric_mean([x["ratio"] for x in lines if x["rayset"] == rs]) for rs in RAYSETS}
    overall = geometric_mean(ratios)
    wts = [x["watertight_ratio"] for x in lines if x["watertight_ratio"] is not None]
    build_lines = one_per_scene(lines)
    builds = [x["build_ratio"] for x in build_lines]
    out = ["Geometric mean of our best / Embree's best: " +
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
    return out


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
        out += ["", range_sentence(rows) + "; for build times, our fastest build against Embree's slowest, and the reverse."]
    noise = run_noise(rows)
    if noise:
        out += ["", noise]
    out += [""] + issue4_targets(lines)
    out += render_each(lines)
    if plot:
        out += ["", f"![Our best and our best watertight backend against Embree, per scene and ray set]({plot})"]
    out += render_threads(rows, lines)
    return "\n".join(out) + "\n"


TARGET_SETS = ("issue33", "issue4", "issue32")
# The one command of a machine's scorecard (--run): the default suite's four ray kinds, one and two
# threads, Embree's medium and high builds beside bvh8, our best candidates and the watertight ones.
RUN_BACKENDS = ("embree,embree:high,bvh8,bvh8:reinsert,bvh8:sbvh:reinsert,bvh8:mt_edges,bvh8:watertight,"
                "bvh8:watertight:reinsert,bvh8:watertight:sbvh:reinsert")
REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def target_sets(text):
    names = [t.strip() for t in text.split(",") if t.strip()]
    unknown = [t for t in names if t not in TARGET_SETS]
    if unknown or not names:
        raise argparse.ArgumentTypeError(f"unknown target set '{','.join(unknown) or text}' (known: issue33, issue4, issue32)")
    return list(dict.fromkeys(names))


def this_machine():
    """{cpu, cpu_id} of this machine as raybench's metadata writes them (harness/src/results/metadata.cpp),
    read from /proc/cpuinfo: enough to name its machine class before the run."""
    fields = {}
    with open("/proc/cpuinfo", encoding="utf-8", errors="replace") as f:
        for line in f:
            if not line.strip():
                break
            key, _, value = line.partition(":")
            fields[key.strip()] = value.strip()
    flags = f" {fields.get('flags', '')} "
    isa = "avx512f" if " avx512f " in flags else "avx2" if " avx2 " in flags else "sse"
    return {"cpu": fields.get("model name", ""),
            "cpu_id": f"family {fields.get('cpu family', '?')} model {fields.get('model', '?')} "
                      f"stepping {fields.get('stepping', '?')}, {isa}"}


def run_command(args, machine_class):
    """The raybench command of --run, and the results CSV it writes, relative to the repository."""
    def in_repo(path):
        """Relative to the repository when inside it (as the metadata's command then reads), else absolute."""
        path = os.path.abspath(path)
        return os.path.relpath(path, REPO) if path.startswith(REPO + os.sep) else path

    def program(name):
        """A bare name stays bare, for the PATH lookup a shell makes; a path is made to work from REPO."""
        return name if os.sep not in name else in_repo(name)
    directory = in_repo(args.machine_dir or os.path.join(REPO, "results", "scorecards"))
    csv_path = os.path.join(directory, f"{machine_class}-run.csv")
    raybench = program(args.raybench) if args.raybench else os.path.join("build", "raybench")
    return ([raybench, "run", "--backend", args.backend, "--rayset", "primary,diffuse,shadow,uniform",
             "--threads", "1,2", "--tessellate", "none", "--out", csv_path] + args.raybench_args, csv_path, directory)


def scorecard_text(rows, meta, source, sets, plot):
    """The Markdown of the first target set's scorecard, with the target tables of the others after it;
    and the summary of issue 33's scorecard (None when it is not the first set)."""
    import machine_scorecard
    lines = scorecard(rows)
    if sets[0] == "issue32":
        if not machine_scorecard.coherent_rows_of(rows):
            raise InputError(source, "no single-thread tiled, diffuse or uniform rows with a packet backend of ours "
                                     "(run meshes/coherent.toml)")
        if not meta:
            raise InputError(source, "no metadata beside it (.meta.toml): the coherent scorecard names the machine "
                                     "class from it")
        out, facts = machine_scorecard.render_coherent_card(rows, meta, source, plot), None
    elif sets[0] == "issue33":
        if not meta:
            raise InputError(source, "no metadata beside it (.meta.toml): issue 33's scorecard names the machine "
                                     "class from it (or pass --targets issue4)")
        if not machine_scorecard.rows_of(rows):
            raise InputError(source, "no single-thread rows of primary, diffuse, shadow or uniform rays with both "
                                     "Embree and one of our backends")
        out, facts = machine_scorecard.render(rows, meta, source, plot)
    else:
        if not lines:
            raise InputError(source, "no single-thread primary, diffuse or shadow rows with both Embree and one of our "
                                     "backends")
        out, facts = render(lines, meta, source, rows, plot).rstrip("\n").split("\n"), None
    for extra in sets[1:]:
        if extra == "issue4":
            out += ["", "## Issue 4's targets (the earlier set)", "",
                    "Our best ≥ 1.0 × Embree's best on every row of the primary, diffuse and shadow rays and ≥ 1.10 as "
                    "their geometric mean, the watertight configuration ≥ 1.0 × `embree`, the default build ≤ 1.0 × "
                    "Embree's medium build, and agreement with Embree:", ""] + (issue4_targets(lines) if lines else
                                                                               ["No rows to hold them to."])
        else:
            evaluated = machine_scorecard.targets(machine_scorecard.rows_of(rows), rows)
            out += ["", "## Issue 33's targets", "", "| target | measured | |", "|---|---|---|"]
            out += [f"| {t['text']} | {t['measured']} | **{t['status']}** |" for t in evaluated]
    if facts:
        out += ["", machine_scorecard.summary_comment(facts)]
    return "\n".join(out) + "\n"


def write_scorecard(results, sets, out, plot, machine_dir):
    """Reads the run, writes the scorecard (stdout without `out`), its picture, and with `machine_dir`
    the index; returns the Markdown's path or None."""
    import machine_scorecard
    meta = read_meta(results)
    rows = attach_round_samples(read_table(results, REQUIRED, NUMERIC), meta, results)
    if machine_dir:
        if not meta:
            raise InputError(results, "no metadata beside it (.meta.toml): cannot name the machine class")
        name = machine_scorecard.machine_class(meta) + ("-coherent" if sets[0] == "issue32" else "")
        out = os.path.join(machine_dir, name + ".md")
        plot = None if plot is False else os.path.join(machine_dir, name + ".png")
    elif plot is None:
        plot = os.path.splitext(out)[0] + ".png" if out else None
    link = None
    if plot:
        if sets[0] == "issue32":
            lines = machine_scorecard.coherent_plot_lines(rows)
            title = "Issue 32: coherent rays, our packets against Embree's packets and streams, one thread"
            if meta.get("cpu_id"):
                title += f" ({machine_scorecard.machine_class(meta)})"
            if lines:
                plot_scorecard(plot, lines, title, machine_scorecard.COHERENT_PANELS,
                               machine_scorecard.TILED_KINDS + machine_scorecard.INCOHERENT_KINDS)
            else:
                plot = None
        elif sets[0] == "issue33":
            lines = machine_scorecard.rows_of(rows)
            panels = (("bvh8_embree", "bvh8_embree_range", "bvh8 / embree", 1.05),
                      ("best_best", "best_best_range", "our best / Embree's best", 1.10),
                      ("wt_embree", "wt_embree_range", "our watertight / embree", 1.05))
            title = "Issue 33: our BVHs against Embree, one thread, same rays, same run"
            if meta.get("cpu_id"):
                title += f" ({machine_scorecard.machine_class(meta)})"
            if lines:
                plot_scorecard(plot, lines, title, panels, machine_scorecard.RAY_KINDS)
            else:
                plot = None
        else:
            lines = scorecard(rows)
            if lines:
                plot_scorecard(plot, lines, "Issue 4: our BVHs against Embree, one thread, same rays, same run")
            else:
                plot = None
        if plot:
            # Linked from the Markdown relative to where it is written.
            link = os.path.relpath(plot, os.path.dirname(os.path.abspath(out))) if out else plot
    text = scorecard_text(rows, meta, results, sets, link)
    if out:
        with open(out, "w", encoding="utf-8") as f:
            f.write(text)
    else:
        sys.stdout.write(text)
    if machine_dir:
        machine_scorecard.write_index(machine_dir)
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("results", nargs="?", help="results CSV of a run with embree (and embree:high) beside our backends")
    parser.add_argument("--targets", type=target_sets, default=["issue33"],
                        help="target sets, the first the scorecard's, the others' tables after it: issue33 (default), "
                             "issue4, or both as issue33,issue4; issue32 alone: the coherent scorecard of a run of "
                             "meshes/coherent.toml (with --machine-dir: DIR/<class>-coherent.md)")
    parser.add_argument("--out", help="write the Markdown here instead of stdout")
    parser.add_argument("--machine-dir", help="write DIR/<machine class>.md (+ .png) and regenerate DIR/README.md, the "
                                              "index; with --run, where the run goes (default results/scorecards)")
    parser.add_argument("--plot", help="the picture of the ratios (PNG; default: beside --out, same name; none without --out)")
    parser.add_argument("--no-plot", action="store_true", help="draw no picture")
    parser.add_argument("--index", metavar="DIR", help="only regenerate DIR/README.md from the scorecards in DIR")
    parser.add_argument("--run", action="store_true", help="run raybench for this machine's scorecard first: "
                        "DIR/<class>-run.csv, then the scorecard and the index (arguments after -- go to raybench)")
    parser.add_argument("--raybench", help="the raybench binary of --run (default build/raybench)")
    parser.add_argument("--backend", default=RUN_BACKENDS, help="the backends of --run (default: %(default)s)")
    parser.add_argument("--dry-run", action="store_true", help="with --run: print the raybench command only")
    argv = list(sys.argv[1:] if argv is None else argv)
    raybench_args = argv[argv.index("--") + 1:] if "--" in argv else []
    args = parser.parse_args(argv[:argv.index("--")] if "--" in argv else argv)
    args.raybench_args = raybench_args
    if sum(map(bool, (args.results, args.index, args.run))) != 1:
        parser.error("give one of: a results CSV, --index DIR, --run")
    if (args.machine_dir or args.run) and (args.out or args.plot):
        print("bvh-scorecard: error: " + ("--run writes DIR/<machine class>.md (+ .png) in --machine-dir DIR (default "
              "results/scorecards)" if args.run else "--machine-dir names the scorecard and its picture") +
              "; no --out or --plot with it", file=sys.stderr)
        return 2
    plot = False if args.no_plot else args.plot
    try:
        import machine_scorecard
        if args.index:
            if not os.path.isdir(args.index):
                raise InputError(args.index, "not a directory")
            count = machine_scorecard.write_index(args.index)
            # The same table for the README's headline, its links relative to the current directory.
            prefix = os.path.relpath(args.index).replace(os.sep, "/") + "/"
            print(f"bvh-scorecard: {os.path.join(args.index, 'README.md')}: {count} machine classes; for a README here:")
            print("\n".join(machine_scorecard.index_lines(args.index, prefix)[0]))
            return 0
        if args.run:
            name = machine_scorecard.machine_class(this_machine())
            command, csv_path, directory = run_command(args, name)
            print(" ".join(shlex.quote(c) for c in command))
            if args.dry_run:
                return 0
            os.makedirs(os.path.join(REPO, directory), exist_ok=True)
            status = subprocess.run(command, cwd=REPO).returncode
            if status != 0:
                raise InputError(command[0], f"raybench run failed (exit {status}); no scorecard written")
            measured = machine_scorecard.machine_class(read_meta(os.path.join(REPO, csv_path)))
            if measured != name:
                raise InputError(csv_path, f"the run's metadata names machine class {measured}, /proc/cpuinfo {name}")
            args.results, args.machine_dir = (os.path.normpath(os.path.join(REPO, p)) for p in (csv_path, directory))
        written = write_scorecard(args.results, args.targets, args.out, plot, args.machine_dir)
        if args.machine_dir:
            print(f"bvh-scorecard: wrote {written} and {os.path.join(args.machine_dir, 'README.md')}")
    except InputError as e:
        print(f"bvh-scorecard: error: {e}", file=sys.stderr)
        return 2
    except OSError as e:
        print(f"bvh-scorecard: error: {e.filename or args.out or args.results}: {e.strerror or e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
