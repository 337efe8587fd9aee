"""Turn a raybench results CSV into a Markdown report with PNG plots.

    scripts/report RESULTS.csv [--out DIR] [--accuracy ACCURACY.csv] [--title TEXT]

Writes DIR/report.md (default DIR: <csv dir>/<csv stem>-report/) and, beside it:

- throughput-<rayset>[-t<threads>].png: median Mrays/s per scene and backend, min-max whiskers;
- ratio-<rayset>[-t<threads>].png: each non-Embree backend's ratio_to_embree per scene;
- pareto-<scene>[-t<threads>].png: speed versus error rate, one panel per ray set, the Pareto
  front joined by a line. Errors come from --accuracy (false_miss + false_hit + wrong_prim,
  fractions of rays) or, without it, from the results themselves as 1 - agree_hit, which is
  disagreement with Embree, not error against a ground truth (on must-hit ray sets, which
  have a `leaks` count, leaks / rays, which is).

The report starts with a "Run" section from the sidecar <csv without .csv>.meta.toml when it
exists, and ends with one table per ray set. Empty CSV fields mean "not applicable" and show "-".

Bad input (missing or empty file, missing schema columns, a field that is not a number) prints
one line `report: error: FILE: problem` on stderr, exits 2 and writes nothing.
"""
import argparse
import csv
import io
import math
import os
import re
import shutil
import sys
import tempfile
import textwrap
import tomllib

REFERENCE = "embree"

# The columns every plot and table needs; the rest of the raybench schema is optional here.
REQUIRED = ["scene", "rayset", "backend", "threads", "mrays_s", "mrays_s_min", "mrays_s_max",
            "ratio_to_embree", "hit_rate", "agree_hit", "agree_prim"]
NUMERIC = ["triangles", "rays", "threads", "build_ms", "build_ms_min", "build_ms_max",
           "memory_bytes", "mrays_s", "mrays_s_min", "mrays_s_max", "reps", "ratio_to_embree",
           "hit_rate", "agree_hit", "agree_prim", "prim_ties", "t_relerr_max", "t_relerr_p999",
           "disagreements", "leaks"]
ACCURACY_REQUIRED = ["scene", "rayset", "backend", "rays", "false_miss", "false_hit",
                     "wrong_prim", "mrays_s"]
ACCURACY_NUMERIC = ["rays", "threads", "false_miss", "false_hit", "wrong_prim", "mrays_s"]

DASH = "\u2013"  # en dash: the "not applicable" mark and the min-max separator
DPI = 110


class InputError(Exception):
    """Bad input: reported as one line `report: error: FILE: problem`, exit status 2."""

    def __init__(self, path, problem):
        super().__init__(f"{path}: {problem}")


# ---------------------------------------------------------------------------------------------
# Reading


def read_table(path, required, numeric):
    """Rows of a CSV as dicts, numeric fields as float (None when empty); InputError if bad."""
    try:
        with open(path, newline="", encoding="utf-8-sig") as f:
            text = f.read()
    except FileNotFoundError:
        raise InputError(path, "no such file")
    except IsADirectoryError:
        raise InputError(path, "is a directory, not a CSV file")
    except UnicodeDecodeError:
        raise InputError(path, "not UTF-8 text")
    except OSError as e:
        raise InputError(path, e.strerror or str(e))
    if not text.strip():
        raise InputError(path, "empty file (no header, no rows)")
    reader = csv.DictReader(io.StringIO(text, newline=""))
    header = [name.strip() for name in reader.fieldnames or []]
    missing = [name for name in required if name not in header]
    if missing:
        raise InputError(path, "missing columns: " + ", ".join(missing))
    reader.fieldnames = header
    rows = []
    for row in reader:
        line = reader.line_num
        if None in row or None in row.values():
            raise InputError(path, f"line {line}: expected {len(header)} fields")
        rows.append(parse_row(path, line, row, numeric))
    if not rows:
        raise InputError(path, "no data rows (header only)")
    return rows


def parse_row(path, line, row, numeric):
    """One CSV row with its numeric fields converted; threads become int."""
    parsed = {key: value.strip() for key, value in row.items()}
    for key in numeric:
        if key not in parsed:
            continue
        text = parsed[key]
        if text == "":
            parsed[key] = None
            continue
        try:
            parsed[key] = float(text)
        except ValueError:
            raise InputError(path, f"line {line}: column {key}: not a number: {text!r}")
    if "threads" in parsed:  # an accuracy file may have no threads column
        threads = parsed["threads"]
        if threads is None or not threads.is_integer():
            raise InputError(path, f"line {line}: column threads: not a whole number: "
                                   f"{row['threads']!r}")
        parsed["threads"] = int(threads)
    for key in ("scene", "rayset", "backend"):
        if not parsed.get(key):
            raise InputError(path, f"line {line}: column {key} is empty")
    return parsed


def meta_path(csv_path):
    """The sidecar raybench writes beside a results CSV: <csv without .csv>.meta.toml."""
    stem, ext = os.path.splitext(csv_path)
    return (stem if ext.lower() == ".csv" else csv_path) + ".meta.toml"


def read_meta(csv_path):
    """The run's metadata as a dict, {} when the sidecar file does not exist."""
    path = meta_path(csv_path)
    if not os.path.exists(path):
        return {}
    try:
        with open(path, "rb") as f:
            return tomllib.load(f)
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as e:
        raise InputError(path, f"not valid TOML: {e}")
    except OSError as e:
        raise InputError(path, e.strerror or str(e))


# ---------------------------------------------------------------------------------------------
# Grouping and formatting


def ordered(values):
    """Distinct values in order of first appearance (the suite's order, not alphabetical)."""
    return list(dict.fromkeys(values))


def safe_name(text):
    """A file-name fragment: scene names may be mesh paths or proc:<name>."""
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text).strip("_.") or "x"


def thread_suffix(threads, all_threads):
    return f"-t{threads}" if len(all_threads) > 1 else ""


def thread_words(threads):
    return f"{threads} thread" + ("" if threads == 1 else "s")


def fmt_sig(value, digits=3):
    """A number to about `digits` significant digits, without exponent notation for big ones."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return DASH
    if abs(value) >= 10 ** digits:
        return f"{value:,.0f}"
    return f"{value:.{digits}g}"


def fmt_fraction(value, digits=6):
    """A fraction near 1 (agreement) that never rounds up to a misleading "1"."""
    if value is None:
        return DASH
    if value == 1:
        return "1"
    text = f"{value:.{digits}g}"
    while text in ("1", "100") and digits < 15:
        digits += 1
        text = f"{value:.{digits}g}"
    return text


def fmt_percent(value):
    if value is None:
        return DASH
    return fmt_fraction(value * 100, 4) + " %"


def fmt_throughput(row):
    median = fmt_sig(row["mrays_s"])
    if row["mrays_s_min"] is None or row["mrays_s_max"] is None:
        return median
    return f"{median} [{fmt_sig(row['mrays_s_min'])}{DASH}{fmt_sig(row['mrays_s_max'])}]"


def fmt_mib(value):
    return DASH if value is None else fmt_sig(value / 2 ** 20)


def fmt_count(value):
    """Triangle counts as 262k / 1.0M: short enough for an axis label."""
    if value is None:
        return ""
    if value >= 1e6:
        return f"{value / 1e6:.1f}M"
    if value >= 1e3:
        return f"{value / 1e3:.0f}k"
    return f"{value:.0f}"


def md_escape(text):
    return str(text).replace("|", "\\|")


def backend_colors(backends):
    """One colour per backend, the same in every figure."""
    from matplotlib import colormaps
    palette = colormaps["tab10" if len(backends) <= 10 else "tab20"].colors
    return {name: palette[i % len(palette)] for i, name in enumerate(backends)}


# ---------------------------------------------------------------------------------------------
# Plots. Each returns nothing and saves one PNG; matplotlib is imported only once the input
# has been validated, so bad input fails fast.


def pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    plt.rcParams.update({"font.size": 9, "axes.titlesize": 10, "figure.titlesize": 11,
                         "axes.spines.top": False, "axes.spines.right": False})
    return plt


def log_axis(ax):
    """A log y axis labelled 0.5, 1, 2, 5, 10, ... rather than only at powers of ten."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter
    ax.set_yscale("log", nonpositive="clip")
    ax.yaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    ax.yaxis.set_minor_formatter(NullFormatter())


def wide_range(values, factor=8.0):
    """True when positive values span more than `factor`: then a log axis reads better."""
    positive = [v for v in values if v is not None and v > 0]
    return len(positive) > 1 and max(positive) / min(positive) > factor


def label_width(groups):
    """Inches a group needs for its scene label: about 0.07 in per 9-pt character."""
    return max(1.15, 0.07 * max((len(g) for g in groups), default=0) + 0.2)


def figure_width(groups, n_series):
    """Wide enough for the bars, each group's label and the legend (2.5 in); past 24 in,
    labels rotate instead (rotate_if_crowded)."""
    per_group = max(label_width(groups), 0.28 * n_series + 0.35)
    return min(24.0, max(7.0, 2.5 + len(groups) * per_group))


def scene_labels(scenes, triangles):
    return [f"{s}\n{fmt_count(triangles.get(s))} tris" if triangles.get(s) else s for s in scenes]


def draw_grouped_bars(ax, scenes, series, colors, value_of, whiskers=True):
    """Bars grouped by scene, one per series; value_of(scene, series) -> (median, lo, hi)."""
    n = max(len(series), 1)
    width = 0.8 / n
    for i, name in enumerate(series):
        xs, heights, lows, highs = [], [], [], []
        for g, scene in enumerate(scenes):
            value = value_of(scene, name)
            if value is None or value[0] is None:
                continue
            median, lo, hi = value
            xs.append(g - 0.4 + width * (i + 0.5))
            heights.append(median)
            lows.append(median - lo if lo is not None else 0.0)
            highs.append(hi - median if hi is not None else 0.0)
        ax.bar(xs, heights, width * 0.92, label=name, color=colors[name], zorder=2)
        if whiskers and xs:
            ax.errorbar(xs, heights, yerr=[lows, highs], fmt="none", ecolor="black",
                        elinewidth=1.0, capsize=max(1.5, 6 / n), capthick=1.0, zorder=3)
    ax.set_xticks(range(len(scenes)))
    ax.set_xlim(-0.6, len(scenes) - 0.4)
    ax.grid(axis="y", which="major", alpha=0.35, zorder=0)


def rotate_if_crowded(ax, fig, groups):
    """Rotate scene labels when the figure, at its widest, still gives a group less room
    than its label needs (some 20 scenes)."""
    if (fig.get_figwidth() - 2.5) / max(len(groups), 1) < 0.95 * label_width(groups):
        for label in ax.get_xticklabels():
            label.set_rotation(30)
            label.set_ha("right")
            label.set_rotation_mode("anchor")


def plot_throughput(path, rows, scenes, backends, colors, title, triangles):
    plt = pyplot()
    by_key = {(r["scene"], r["backend"]): r for r in rows}

    def value_of(scene, backend):
        row = by_key.get((scene, backend))
        return None if row is None else (row["mrays_s"], row["mrays_s_min"], row["mrays_s_max"])

    fig, ax = plt.subplots(figsize=(figure_width(scenes, len(backends)), 4.8),
                           layout="constrained")
    draw_grouped_bars(ax, scenes, backends, colors, value_of)
    values = [r[k] for r in rows for k in ("mrays_s", "mrays_s_min", "mrays_s_max")]
    if wide_range(values):
        log_axis(ax)
        ax.set_ylabel("throughput (Mrays/s, log scale)")
    else:
        ax.set_ylabel("throughput (Mrays/s)")
    ax.set_xticklabels(scene_labels(scenes, triangles))
    rotate_if_crowded(ax, fig, scenes)
    ax.set_title(wrap_title(title, fig))
    ax.legend(title="backend (median, whisker: min\u2013max)", loc="upper left",
              bbox_to_anchor=(1.0, 1.0), frameon=False)
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def wrap_title(text, fig):
    """Titles wrapped to the figure: a one-scene figure is narrower than its title."""
    width = max(30, int(fig.get_figwidth() * 10))
    return "\n".join(textwrap.fill(line, width) for line in text.splitlines())


def geometric_mean(values):
    positive = [v for v in values if v is not None and v > 0]
    return math.exp(sum(map(math.log, positive)) / len(positive)) if positive else None


def plot_ratio(path, rows, scenes, backends, colors, title, triangles):
    plt = pyplot()
    by_key = {(r["scene"], r["backend"]): r["ratio_to_embree"] for r in rows}
    # A last group with each backend's geometric mean over scenes: the one-number summary.
    summary = ["geo. mean"] if len(scenes) > 1 else []
    groups = scenes + summary
    means = {b: geometric_mean([by_key.get((s, b)) for s in scenes]) for b in backends}

    def value_of(scene, backend):
        ratio = means[backend] if scene == "geo. mean" else by_key.get((scene, backend))
        return None if ratio is None else (ratio, None, None)

    fig, ax = plt.subplots(figsize=(figure_width(groups, len(backends)), 4.8),
                           layout="constrained")
    draw_grouped_bars(ax, groups, backends, colors, value_of, whiskers=False)
    ax.axhline(1.0, color="black", linewidth=1.2, linestyle="--", zorder=4,
               label="Embree (= 1.0)")
    if summary:
        ax.axvline(len(scenes) - 0.5, color="grey", linewidth=0.8, zorder=1)
    ratios = [v for v in by_key.values() if v is not None] + [1.0]
    if wide_range(ratios, 20):
        log_axis(ax)
        ax.set_ylabel("throughput / Embree's (log scale)")
    else:
        ax.set_ylim(0, max(ratios) * 1.12)
        ax.set_ylabel("throughput / Embree's (\u00d7)")
    if len(backends) <= 3:
        label_bars(ax)
    ax.set_xticklabels(scene_labels(scenes, triangles) + summary)
    rotate_if_crowded(ax, fig, groups)
    ax.set_title(wrap_title(title, fig))
    ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0), frameon=False)
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def label_bars(ax):
    """Write each bar's value above it: readable when there are few bars per scene."""
    for container in ax.containers:
        if hasattr(container, "patches") and container.patches:
            ax.bar_label(container, fmt="%.2f", fontsize=7, padding=1.5)


def pareto_front(points):
    """The points no other point beats on both speed (higher) and error (lower), by error."""
    front = []
    for p in points:
        dominated = any(q["speed"] >= p["speed"] and q["error"] <= p["error"]
                        and (q["speed"] > p["speed"] or q["error"] < p["error"]) for q in points)
        if not dominated:
            front.append(p)
    return sorted(front, key=lambda p: (p["error"], -p["speed"]))


def symlog_threshold(errors, rays):
    """Below this the x axis is linear: one ray's error, or the smallest error seen."""
    candidates = [e for e in errors if e > 0] + ([1.0 / rays] if rays else [1e-6])
    return 10.0 ** math.floor(math.log10(min(candidates)))


def plot_pareto(path, panels, colors, title, notes):
    """panels: [(rayset, [point]), ...]; point: dict(backend, error, speed, rays)."""
    plt = pyplot()
    ncols = min(len(panels), 4)
    nrows = math.ceil(len(panels) / ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(4.1 * ncols + 0.4, 3.7 * nrows + 0.7),
                             layout="constrained", squeeze=False)
    for ax in axes.flat[len(panels):]:
        ax.set_visible(False)
    for ax, (rayset, points) in zip(axes.flat, panels):
        draw_pareto_panel(ax, rayset, points, colors)
    legend = ("filled: the Pareto front (dashed line), no other backend both faster and more "
              "accurate; hollow: dominated")
    fig.suptitle(wrap_title("\n".join([title, *notes, legend]), fig))
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def draw_pareto_panel(ax, rayset, points, colors):
    errors = [p["error"] for p in points]
    rays = max((p["rays"] or 0 for p in points), default=0)
    threshold = symlog_threshold(errors, rays)
    front = pareto_front(points)
    ax.plot([p["error"] for p in front], [p["speed"] for p in front], color="grey",
            linestyle="--", linewidth=1.2, zorder=1, label="Pareto front")
    on_front = {id(p) for p in front}
    for p in points:
        filled = id(p) in on_front
        ax.scatter([p["error"]], [p["speed"]], s=42, zorder=3, linewidths=1.5,
                   color=colors[p["backend"]] if filled else "white",
                   edgecolors=colors[p["backend"]])
    ax.set_xscale("symlog", linthresh=threshold, linscale=0.6)
    ax.set_xlim(-0.6 * threshold, max(max(errors) * 4, threshold * 100))
    speeds = [p["speed"] for p in points]
    if wide_range(speeds, 10):
        log_axis(ax)
        ax.set_ylim(min(speeds) / 1.5, max(speeds) * 1.5)  # room for the labels
    else:
        ax.set_ylim(0, max(speeds) * 1.2)
    annotate_points(ax, points)
    ax.set_title(rayset)
    ax.set_xlabel(ERROR_KINDS[points[0]["kind"]][0])
    ax.set_ylabel("throughput (Mrays/s)")
    ax.grid(alpha=0.3, zorder=0)


def annotate_points(ax, points):
    """Backend names beside their points, nudged apart vertically where labels would overlap.

    Works in axes fractions (data -> [0, 1]) with estimated label widths rather than measured
    pixels: a full canvas draw per panel to measure them would triple the rendering time."""
    ax.autoscale_view()
    to_axes = (ax.transScale + ax.transLimits).transform
    height_pt = ax.figure.get_figheight() * 72 * ax.get_position().height
    width_pt = ax.figure.get_figwidth() * 72 * ax.get_position().width
    min_gap = 10.0 / height_pt  # one line of 8-pt text
    placed = []  # (x0, x1, y) of labels already placed, in axes fractions
    for p in sorted(points, key=lambda p: -p["speed"]):
        x, y = to_axes((p["error"], p["speed"]))
        pad, width = 5.0 / width_pt, (5.0 * len(p["backend"]) + 2) / width_pt
        left = x + pad + width > 1.0  # would leave the axes: put it left of the point
        x0, x1 = (x - pad - width, x - pad) if left else (x + pad, x + pad + width)
        label_y, moved = y, True
        while moved:  # each move goes strictly down (0.99: rounding), so this ends
            moved = False
            for px0, px1, py in placed:
                if x0 < px1 and px0 < x1 and abs(py - label_y) < 0.99 * min_gap:
                    label_y, moved = py - min_gap, True
        placed.append((x0, x1, label_y))
        ax.annotate(p["backend"], (p["error"], p["speed"]),
                    xytext=(-5 if left else 5, 2 + (label_y - y) * height_pt),
                    textcoords="offset points", fontsize=8, va="bottom",
                    ha="right" if left else "left",
                    arrowprops=None if label_y == y else {"arrowstyle": "-", "color": "0.6",
                                                          "linewidth": 0.6})


# ---------------------------------------------------------------------------------------------
# What to plot


class Plot:
    """One PNG: where it goes in the report and how to draw it."""

    def __init__(self, section, heading, sentence, filename, draw):
        self.section, self.heading, self.sentence = section, heading, sentence
        self.filename, self.draw = filename, draw


def rayset_caption(rows, rayset):
    query = next((r.get("query") for r in rows if r["rayset"] == rayset and r.get("query")), "")
    return f"{rayset} rays" + (f" ({'any hit' if query == 'occluded' else 'closest hit'})"
                               if query else "")


def rays_words(rows):
    counts = ordered(int(r["rays"]) for r in rows if r.get("rays"))
    return f"{counts[0]:,} rays per scene; " if len(counts) == 1 else ""


def throughput_plots(rows, scenes, backends, raysets, all_threads, colors, triangles):
    plots = []
    for rayset in raysets:
        for threads in all_threads:
            subset = [r for r in rows if r["rayset"] == rayset and r["threads"] == threads]
            if not subset:
                continue
            present = [b for b in backends if any(r["backend"] == b for r in subset)]
            in_plot = [sc for sc in scenes if any(r["scene"] == sc for r in subset)]
            reps = ordered(int(r["reps"]) for r in subset if r.get("reps"))
            reps_text = f"{reps[0]} repetitions" if len(reps) == 1 else "repetitions"
            title = (f"Throughput, {rayset_caption(rows, rayset)}, {thread_words(threads)}\n"
                     f"{rays_words(subset)}higher is better")
            filename = f"throughput-{safe_name(rayset)}{thread_suffix(threads, all_threads)}.png"
            plots.append(Plot(
                "Throughput", f"{rayset_caption(rows, rayset)}, {thread_words(threads)}",
                f"One group per scene, one bar per backend: the median Mrays/s over {reps_text}, "
                "whiskers from the slowest to the fastest repetition; higher is faster.",
                filename,
                lambda path, s=subset, sc=in_plot, p=present, t=title: plot_throughput(
                    path, s, sc, p, colors, t, triangles)))
    return plots


def ratio_plots(rows, scenes, backends, raysets, all_threads, colors, triangles):
    plots = []
    others = [b for b in backends if b != REFERENCE]
    for rayset in raysets:
        for threads in all_threads:
            subset = [r for r in rows if r["rayset"] == rayset and r["threads"] == threads
                      and r["backend"] != REFERENCE and r["ratio_to_embree"] is not None]
            if not subset:
                continue
            present = [b for b in others if any(r["backend"] == b for r in subset)]
            in_plot = [sc for sc in scenes if any(r["scene"] == sc for r in subset)]
            mean = " (the last group is the geometric mean over scenes)" if len(in_plot) > 1 else ""
            title = (f"Ratio to Embree, {rayset_caption(rows, rayset)}, {thread_words(threads)}\n"
                     "measured within one run: same rays, interleaved repetitions")
            filename = f"ratio-{safe_name(rayset)}{thread_suffix(threads, all_threads)}.png"
            plots.append(Plot(
                "Ratio to Embree", f"{rayset_caption(rows, rayset)}, {thread_words(threads)}",
                f"Each bar is a backend's median throughput divided by Embree's in the same run"
                f"{mean}; above the dashed line at 1.0 is faster than Embree, below is slower.",
                filename,
                lambda path, s=subset, sc=in_plot, p=present, t=title: plot_ratio(
                    path, s, sc, p, colors, t, triangles)))
    return plots


# What a point's error means, by where it came from: the x-axis label and the figure's note.
ERROR_KINDS = {
    "accuracy": ("error rate (fraction of rays, symlog)",
                 "error = false miss + false hit + wrong triangle, as fractions of rays "
                 "(from the accuracy file)"),
    "disagree": ("1 \u2212 agree_hit: disagreement with Embree (symlog)",
                 "error = 1 \u2212 agree_hit: hit/miss DISAGREEMENT WITH EMBREE "
                 "(not ground truth; Embree is 0 by definition)"),
    "leaks": ("leaked rays / rays (every ray must hit; symlog)",
              "must-hit ray sets: error = leaks / rays, ground truth (every ray must hit)"),
}


def error_points_from_accuracy(accuracy):
    """(scene, rayset, threads) -> points, error = false_miss + false_hit + wrong_prim."""
    groups = {}
    for r in accuracy:
        if r["mrays_s"] is None:
            continue
        parts = [r[k] for k in ("false_miss", "false_hit", "wrong_prim") if r[k] is not None]
        if not parts:
            continue
        point = {"backend": r["backend"], "error": sum(parts), "speed": r["mrays_s"],
                 "rays": r["rays"], "kind": "accuracy"}
        groups.setdefault((r["scene"], r["rayset"], r.get("threads")), []).append(point)
    return groups


def error_points_from_results(rows):
    """The fallback without an accuracy file: 1 - agree_hit (hit/miss disagreement with
    Embree), except on must-hit ray sets, where `leaks` / rays is a true error rate and
    Embree itself leaks, so disagreement with it would mislead."""
    groups = {}
    for r in rows:
        if r["mrays_s"] is None:
            continue
        if r.get("leaks") is not None and r.get("rays"):
            error, kind = r["leaks"] / r["rays"], "leaks"
        elif r["agree_hit"] is not None:
            error, kind = max(0.0, 1.0 - r["agree_hit"]), "disagree"
        else:
            continue
        point = {"backend": r["backend"], "error": error, "speed": r["mrays_s"],
                 "rays": r.get("rays"), "kind": kind}
        groups.setdefault((r["scene"], r["rayset"], r["threads"]), []).append(point)
    return groups


def pareto_sentence(kinds):
    if "accuracy" in kinds:
        error = "more rays answered wrongly"
    elif kinds == {"leaks"}:
        error = "more rays leaked through a closed mesh"
    else:
        error = ("more rays on which it disagrees with Embree about hit or miss (not an error "
                 "against ground truth: Embree itself sits at 0 by definition)")
        if "leaks" in kinds:
            error += "; on must-hit ray sets, more rays leaked (ground truth)"
    return (f"Each point is a backend, further right = {error}, higher = faster; the dashed "
            "line joins the Pareto front (backends no other backend beats on both speed and "
            "error), drawn as filled points.")


def pareto_plots(groups, raysets, colors, triangles):
    scenes = ordered(key[0] for key in groups)
    raysets = [rs for rs in raysets if any(k[1] == rs for k in groups)] + \
        ordered(k[1] for k in groups if k[1] not in raysets)
    all_threads = sorted(ordered(k[2] for k in groups), key=lambda t: (t is None, t or 0))
    plots, used = [], set()
    for scene in scenes:
        for threads in all_threads:
            panels = [(rs, groups[(scene, rs, threads)]) for rs in raysets
                      if (scene, rs, threads) in groups]
            if not panels:
                continue
            kinds = {p["kind"] for _, points in panels for p in points}
            suffix = f"-t{threads}" if len(all_threads) > 1 and threads is not None else ""
            filename = unique_name(f"pareto-{safe_name(scene)}{suffix}", used)
            tris = triangles.get(scene)
            heading = scene + (f", {thread_words(threads)}" if suffix else "")
            title = (f"Speed versus error: {scene}" + (f" ({tris:,.0f} triangles)" if tris else "")
                     + (f", {thread_words(threads)}" if suffix else ""))
            notes = [ERROR_KINDS[k][1] for k in ERROR_KINDS if k in kinds]
            plots.append(Plot("Speed versus error", heading, pareto_sentence(kinds), filename,
                              lambda path, p=panels, t=title, n=notes: plot_pareto(
                                  path, p, colors, t, n)))
    return plots


def unique_name(stem, used):
    """stem.png, or stem-2.png when two scene names sanitise to the same file name."""
    name, n = f"{stem}.png", 1
    while name in used:
        n += 1
        name = f"{stem}-{n}.png"
    used.add(name)
    return name


# ---------------------------------------------------------------------------------------------
# Markdown


def run_facts(meta):
    """(label, text) pairs for the Run section, from the metadata raybench writes (all strings);
    keys that are absent are left out, so older or hand-written files still work."""
    m = {key: str(value) for key, value in meta.items() if str(value) != ""}
    cpu = m.get("cpu")
    if cpu and m.get("hardware_threads"):
        cpu += f" ({m['hardware_threads']} hardware threads)"
    commit = m.get("git_commit")
    if commit:
        commit = f"`{commit}`" + (" (uncommitted changes)" if commit.endswith("-dirty") else "")
    rays = m.get("rays")
    if rays and rays.isdigit():
        rays = f"{int(rays):,}"
    reps = m.get("repetitions")
    if reps:
        reps += " timed" + (", interleaved" if m.get("interleaved") == "true" else "")
    return [("Date", m.get("date")),
            ("CPU", cpu),
            ("Host / OS", " / ".join(m[k] for k in ("host", "os") if k in m)),
            ("Compiler", " ".join(m[k] for k in ("compiler", "build_type") if k in m)),
            ("Flags", m.get("flags") and f"`{m['flags']}`"),
            ("Embree", m.get("embree")),
            ("Git commit", commit),
            ("Threads", m.get("threads")),
            ("Rays per ray set", rays),
            ("Repetitions", reps),
            ("Seed", m.get("seed")),
            ("Command", m.get("command") and f"`{m['command']}`")]


def run_section(meta, csv_path, rows):
    lines = ["## Run", "", f"- Results: `{os.path.basename(csv_path)}`"]
    if not meta:
        threads = ", ".join(str(t) for t in sorted(ordered(r["threads"] for r in rows)))
        lines.append(f"- Metadata: none (`{os.path.basename(meta_path(csv_path))}` not found)")
        lines.append(f"- Threads: {threads}")
        return lines + [""]
    lines.append(f"- Metadata: `{os.path.basename(meta_path(csv_path))}`")
    lines += [f"- {label}: {text}" for label, text in run_facts(meta) if text]
    return lines + [""]


TABLE_HEADER = ["scene", "backend", "threads", "Mrays/s [min\u2013max]", "\u00d7 Embree",
                "hit rate", "agree_hit", "agree_prim", "build ms", "MiB"]


def table_row(row, with_leaks):
    cells = [md_escape(row["scene"]), md_escape(row["backend"]), str(row["threads"]),
             fmt_throughput(row), fmt_sig(row["ratio_to_embree"]), fmt_percent(row["hit_rate"]),
             fmt_fraction(row["agree_hit"]), fmt_fraction(row["agree_prim"]),
             fmt_sig(row.get("build_ms")), fmt_mib(row.get("memory_bytes"))]
    if with_leaks:
        cells.append(DASH if row.get("leaks") is None else f"{row['leaks']:,.0f}")
    return cells


def tables_section(rows, scenes, backends, raysets):
    lines = ["## Tables", "",
             f"Empty cells ({DASH}) are not applicable: occlusion queries report no triangle, "
             "so shadow rays have no agree_prim. Hit rate is the fraction of rays the backend "
             "reports hit (occluded for shadow rays); leaks, on must-hit ray sets only, counts "
             "the rays it lets through a closed mesh.", ""]
    for rayset in raysets:
        subset = sorted((r for r in rows if r["rayset"] == rayset),
                        key=lambda r: (scenes.index(r["scene"]), r["threads"],
                                       backends.index(r["backend"])))
        # Must-hit ray sets count the rays a backend lets through a closed mesh.
        with_leaks = any(r.get("leaks") is not None for r in subset)
        header = TABLE_HEADER + (["leaks"] if with_leaks else [])
        lines += [f"### {rayset_caption(rows, rayset)}", "",
                  "| " + " | ".join(header) + " |",
                  "|" + "|".join("---:" if i >= 3 else "---" for i in range(len(header))) + "|"]
        lines += ["| " + " | ".join(table_row(r, with_leaks)) + " |" for r in subset]
        lines.append("")
    return lines


def plots_section(plots, intro):
    lines = []
    for section in ordered(p.section for p in plots):
        lines += [f"## {section}", ""]
        if intro.get(section):
            lines += [intro[section], ""]
        for p in (p for p in plots if p.section == section):
            lines += [f"### {p.heading}", "", p.sentence, "", f"![{p.heading}]({p.filename})", ""]
    return lines


def render_markdown(title, meta, csv_path, rows, plots, intro, scenes, backends, raysets):
    lines = [f"# {title}", ""]
    lines += run_section(meta, csv_path, rows)
    lines += plots_section(plots, intro)
    lines += tables_section(rows, scenes, backends, raysets)
    return "\n".join(lines).rstrip() + "\n"


# ---------------------------------------------------------------------------------------------
# Output


def write_report(out_dir, plots, markdown):
    """Draw every PNG and report.md in a staging folder inside out_dir, then move them in,
    report.md last: a failure part-way leaves no half-written report.md behind."""
    created = not os.path.isdir(out_dir)
    os.makedirs(out_dir, exist_ok=True)
    stage = tempfile.mkdtemp(prefix=".report-", dir=out_dir)
    try:
        for p in plots:
            p.draw(os.path.join(stage, p.filename))
        with open(os.path.join(stage, "report.md"), "w", encoding="utf-8") as f:
            f.write(markdown)
        for p in plots:
            os.replace(os.path.join(stage, p.filename), os.path.join(out_dir, p.filename))
        os.replace(os.path.join(stage, "report.md"), os.path.join(out_dir, "report.md"))
    except BaseException:
        shutil.rmtree(stage, ignore_errors=True)
        if created and not os.listdir(out_dir):
            os.rmdir(out_dir)
        raise
    shutil.rmtree(stage, ignore_errors=True)


def default_out_dir(csv_path):
    folder, name = os.path.split(os.path.abspath(csv_path))
    return os.path.join(folder, os.path.splitext(name)[0] + "-report")


class Parser(argparse.ArgumentParser):
    """argparse with raybench's one-line error convention instead of usage + message."""

    def error(self, message):
        sys.stderr.write(f"report: error: {message}\n")
        sys.exit(2)


def parse_args(argv):
    parser = Parser(prog="scripts/report", description=__doc__.split("\n\n")[0],
                    epilog="Writes DIR/report.md and PNG plots beside it; see the top of "
                           "scripts/report.py for what each plot shows.")
    parser.add_argument("csv", metavar="RESULTS.csv", help="a raybench results CSV")
    parser.add_argument("--out", metavar="DIR",
                        help="output folder (default: <csv dir>/<csv stem>-report/)")
    parser.add_argument("--accuracy", metavar="ACCURACY.csv",
                        help="accuracy CSV (scene, rayset, backend, rays, false_miss, false_hit, "
                             "wrong_prim, mrays_s) for the speed-versus-error plots; without it "
                             "they use 1 - agree_hit (disagreement with Embree)")
    parser.add_argument("--title", metavar="TEXT", help="report title")
    return parser.parse_args(argv)


def main(argv):
    args = parse_args(argv)
    rows = read_table(args.csv, REQUIRED, NUMERIC)
    meta = read_meta(args.csv)
    accuracy = read_table(args.accuracy, ACCURACY_REQUIRED, ACCURACY_NUMERIC) \
        if args.accuracy else None
    out_dir = args.out or default_out_dir(args.csv)
    if os.path.exists(out_dir) and not os.path.isdir(out_dir):
        raise InputError(out_dir, "exists and is not a directory")

    scenes = ordered(r["scene"] for r in rows)
    raysets = ordered(r["rayset"] for r in rows)
    # The reference first, then the order the run listed its backends in.
    backends = sorted(ordered(r["backend"] for r in rows), key=lambda b: b != REFERENCE)
    all_threads = sorted(ordered(r["threads"] for r in rows))
    triangles = {r["scene"]: r.get("triangles") for r in rows if r.get("triangles")}
    extra = ordered(r["backend"] for r in accuracy or [] if r["backend"] not in backends)
    colors = backend_colors(backends + extra)

    groups = error_points_from_accuracy(accuracy) if accuracy else error_points_from_results(rows)
    plots = (throughput_plots(rows, scenes, backends, raysets, all_threads, colors, triangles)
             + ratio_plots(rows, scenes, backends, raysets, all_threads, colors, triangles)
             + pareto_plots(groups, raysets, colors, triangles))
    intro = {"Ratio to Embree": "Ratios are measured within one run (same rays, same machine, "
                                "repetitions interleaved), so they are more stable across runs "
                                "than absolute Mrays/s.",
             "Speed versus error": (f"Errors from `{os.path.basename(args.accuracy)}`."
                                    if accuracy else
                                    "No accuracy file given (`--accuracy`): the error here is "
                                    "1 \u2212 agree_hit, disagreement with Embree, not an error "
                                    "against ground truth; on must-hit ray sets (a `leaks` "
                                    "value) it is leaks / rays, which is one.")}
    title = args.title or f"raybench report: {os.path.splitext(os.path.basename(args.csv))[0]}"
    markdown = render_markdown(title, meta, args.csv, rows, plots, intro, scenes, backends,
                               raysets)
    write_report(out_dir, plots, markdown)
    print(os.path.join(out_dir, "report.md"))
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv[1:]))
    except InputError as e:
        sys.stderr.write(f"report: error: {e}\n")
        sys.exit(2)
    except OSError as e:
        sys.stderr.write(f"report: error: {e.filename or 'output'}: {e.strerror or e}\n")
        sys.exit(1)
