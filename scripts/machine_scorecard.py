"""Issue 33's scorecard, one per machine class, and the index of every machine class measured.

A machine class is the CPU's vendor, family and model as the run's metadata records them (`cpu`,
`cpu_id` "family 6 model 167 stepping 1, avx512f"): intel-family6-model167, amd-family26-model2.
Embree is a different opponent on each (its AVX-512 kernels are strong on Intel, slow on Zen's
compress instructions), so each class gets its own scorecard, results/scorecards/<class>.md, made
from a full run committed beside it as <class>-run.csv (+ .meta.toml).

Issue 33's targets, one thread unless said, ratios within the run, each row's ratio with its range
over the repetitions (bvh_scorecard.ratio_with_range: paired by round in a run timed in rounds):
- `bvh8` >= 1.05 x `embree` on every scene x ray kind (primary, diffuse, shadow, uniform), and
  >= 1.0 x Embree's best of `embree` and `embree:high`;
- our best >= 1.30 x Embree's best as a geometric mean over the primary, diffuse and shadow rows,
  and >= 1.10 on every one of them;
- the watertight configuration (bvh_scorecard.is_watertight) >= 1.05 x `embree` on every row of
  the four ray kinds;
- the default build (`bvh8`) <= 1.0 x Embree's medium build (`embree`), with one thread and two.
A target whose rows the run lacks (a ray kind, the two-thread rows, a watertight backend) is
"not measurable", never met. A missed per-row target names its rows, each within the noise of
the repetitions (its range reaches the target) or beyond it.

Issue 32's coherent section, when the run has tiled rows (meshes/coherent.toml), one thread:
- on primary-tiled and shadow-tiled, our best coherent mode (a backend of ours whose name has a
  `packet` option) >= 1.30 x Embree's best coherent mode (the fastest of its `packet4/8/16` and
  `stream` modes in the run, with the coherent or the incoherent context flag: on shadow rays
  `embree:stream:incoherent` is Embree's fastest) on every row, and >= 2.0 x `embree`
  (rtcIntersect1) as a geometric mean over those rows;
- on diffuse and uniform rays every packet backend of ours >= 0.95 x the same backend without
  `packet` (it falls back to single rays, so a user can leave it on).

Each scorecard ends with a machine-readable summary (an HTML comment) that write_index reads back
to make results/scorecards/README.md: one line per machine class.
"""
import json
import os
import re
import tomllib

from bvh_scorecard import is_ours, is_watertight, range_sentence, ratio_range, ratio_with_range, run_noise, verdict
from report import InputError, geometric_mean, read_meta

RAY_KINDS = ("primary", "diffuse", "shadow", "uniform")
TRACED_KINDS = ("primary", "diffuse", "shadow")  # the kinds of the our-best targets
TILED_KINDS = ("primary-tiled", "shadow-tiled")  # issue 32's coherent targets
INCOHERENT_KINDS = ("diffuse", "uniform")  # where a packet backend must cost nothing
EMBREE_COHERENT_MODES = ("packet4", "packet8", "packet16", "stream")
SUMMARY_MARK = "<!-- machine-scorecard-summary "


def machine_class(meta):
    """intel-family6-model167 from the metadata's `cpu` (model name: the vendor) and `cpu_id`
    (family and model); the vendor is "unknown" when the model name names neither Intel nor AMD.
    InputError without a cpu_id that names a family and model."""
    cpu_id = str(meta.get("cpu_id", ""))
    match = re.search(r"family\s+(\d+)\s+model\s+(\d+)", cpu_id)
    if not match:
        raise InputError("metadata", "no cpu_id naming the CPU's family and model (e.g. 'family 6 model 167 "
                         "stepping 1, avx512f'): cannot name the machine class" if not cpu_id else
                         f"cpu_id '{cpu_id}' names no family and model: cannot name the machine class")
    cpu = str(meta.get("cpu", ""))
    vendor = ("intel" if re.search(r"intel", cpu, re.I) else "amd" if re.search(r"\bamd\b|authenticamd", cpu, re.I)
              else "unknown")
    return f"{vendor}-family{match.group(1)}-model{match.group(2)}"


def cpu_isa(meta):
    """The widest vector instructions cpu_id names ("avx512f", "avx2", "sse"), or None."""
    parts = str(meta.get("cpu_id", "")).split(",", 1)
    return parts[1].strip() or None if len(parts) == 2 else None


# Where the Embree backends' metadata records each fact, as harness/src/backends/embree_selection.cpp
# writes it: provenance.<embree backend>.<field>. The BVH type is `accel` with its `leaf` ("BVH8
# Triangle4"); the memory policy is the run's top-level memory_policy (one policy for every backend,
# in the kernel's THP mode), else the backends' own `huge_pages` (on/off).
NOT_RECORDED = "not recorded"
PREDATES_EMBREE_FIX = ("This run predates issue 33's Embree wrapper fix and memory policy (its metadata records no "
                       "Embree provenance): Embree was traced through a slower loop, so its ratios overstate ours.")


def embree_provenance(meta):
    """{embree backend: its provenance fields}; {} for a run that predates issue 33's Embree wrapper."""
    provenance = meta.get("provenance") if isinstance(meta.get("provenance"), dict) else {}
    return {b: fields for b, fields in provenance.items() if b.startswith("embree") and isinstance(fields, dict)}


def _text(value):
    return str(value).lower() if isinstance(value, bool) else str(value)


def _bvh_type(fields):
    if "accel" not in fields:
        return None
    return f"{fields['accel']} {fields['leaf']}" if fields.get("leaf") else _text(fields["accel"])


def _merged(per):
    """One text for every backend when they agree, else "embree: x; embree:high: y"."""
    if not per:
        return NOT_RECORDED
    if len(set(per.values())) == 1:
        return next(iter(per.values()))
    return "; ".join(f"{b}: {v}" for b, v in per.items())


def embree_config(meta):
    """{fact: text} for Embree's ISA, BVH type and memory policy; per backend when `embree` and
    `embree:high` differ ("embree: BVH4 Triangle4; embree:high: BVH8 Triangle4"); NOT_RECORDED when
    absent."""
    embrees = embree_provenance(meta)
    isa = {b: _text(f["isa"]) for b, f in embrees.items() if "isa" in f}
    bvh = {b: t for b, t in ((b, _bvh_type(f)) for b, f in embrees.items()) if t is not None}
    if "memory_policy" in meta:
        memory = str(meta["memory_policy"])
    else:
        memory = _merged({b: f"huge pages {_text(f['huge_pages'])}" for b, f in embrees.items() if "huge_pages" in f})
    return {"ISA": _merged(isa), "BVH type": _merged(bvh), "memory policy": memory}


def fastest(backends, names):
    present = [(b, backends[b]) for b in names if b in backends]
    return max(present, key=lambda kv: kv[1]["mrays_s"]) if present else (None, None)


def rows_of(rows, threads=1):
    """Per (scene, ray kind) at `threads`, in the run's order: the ratios of issue 33's targets."""
    by = {}
    for r in rows:
        if r["threads"] == threads and r["rayset"] in RAY_KINDS and r["mrays_s"]:
            by.setdefault((r["scene"], r["rayset"]), {})[r["backend"]] = r
    lines = []
    for (scene, kind), backends in by.items():
        embree = backends.get("embree")
        best_embree_name, best_embree = fastest(backends, ("embree", "embree:high"))
        ours = {b: r for b, r in backends.items() if is_ours(b)}
        if best_embree is None or not ours:
            continue
        best_name, best = fastest(ours, list(ours))
        wt_name, wt = fastest(ours, [b for b in ours if is_watertight(b)])
        line = {"scene": scene, "rayset": kind, "best_embree": best_embree_name, "best": best_name,
                "watertight": wt_name}
        for key, (a, b) in {"bvh8_embree": (backends.get("bvh8"), embree),
                            "bvh8_best": (backends.get("bvh8"), best_embree),
                            "best_best": (best, best_embree), "wt_embree": (wt, embree)}.items():
            line[key], line[key + "_range"] = ratio_with_range(a, b)
        lines.append(line)
    return lines


def build_ratios(rows, threads):
    """Per scene at `threads`: (scene, bvh8 build / embree build, its range over the timed builds)."""
    by = {}
    for r in rows:
        if r["threads"] == threads and r["backend"] in ("bvh8", "embree") and r.get("build_ms"):
            by.setdefault(r["scene"], {})[r["backend"]] = r
    return [(scene, b["bvh8"]["build_ms"] / b["embree"]["build_ms"], ratio_range(b["bvh8"], b["embree"], "build_ms"))
            for scene, b in by.items() if "bvh8" in b and "embree" in b]


def fmt_ratio(value, span):
    if value is None:
        return "-"
    return f"{value:.2f}" + ("" if span is None else f" ({span[0]:.2f}–{span[1]:.2f})")


def per_row_target(text, lines, key, threshold, kinds, absent):
    """A target held on every row of `kinds`: its verdict, the measured minimum and the rows that
    miss it (each within the noise of the repetitions, or beyond). `absent` says what the run
    lacks when no row has the ratio."""
    measured = [x for x in lines if x["rayset"] in kinds and x[key] is not None]
    missing_kinds = [k for k in kinds if not any(x["rayset"] == k for x in measured)]
    target = {"text": text, "misses": []}
    if not measured:
        return {**target, "status": "not measurable", "measured": f"no rows: {absent}"}
    worst = min(measured, key=lambda x: x[key])
    for x in measured:
        if x[key] < threshold:
            span = x[key + "_range"]
            noise = "" if span is None else (", within noise" if span[1] >= threshold else ", beyond noise")
            target["misses"].append(f"{x['scene']} {x['rayset']} {fmt_ratio(x[key], span)}{noise}")
    text = f"min {worst[key]:.2f} ({worst['scene']} {worst['rayset']})"
    if target["misses"]:
        text += f"; {len(target['misses'])} of {len(measured)} rows below {threshold:.2f}"
    if missing_kinds:
        return {**target, "status": "not measurable",
                "measured": f"{text}; the run has no {', '.join(missing_kinds)} rows"}
    return {**target, "status": "met" if not target["misses"] else "missed", "measured": text}


def build_target(text, builds, absent):
    target = {"text": text, "misses": []}
    if not builds:
        return {**target, "status": "not measurable", "measured": f"no rows: {absent}"}
    for scene, value, span in builds:
        if value > 1.0:
            noise = "" if span is None else (", within noise" if span[0] <= 1.0 else ", beyond noise")
            target["misses"].append(f"{scene} {fmt_ratio(value, span)}{noise}")
    worst = max(builds, key=lambda b: b[1])
    measured = f"max {worst[1]:.2f} ({worst[0]})"
    if target["misses"]:
        measured += f"; {len(target['misses'])} of {len(builds)} scenes above 1.00"
    return {**target, "status": "met" if not target["misses"] else "missed", "measured": measured}


def geomean_target(text, values, missing, threshold):
    """A geometric-mean target: met when the mean of `values` reaches `threshold`; not measurable
    without values or when the run lacks the ray kinds in `missing`."""
    mean = geometric_mean(values)
    target = {"text": text, "misses": []}
    if mean is None or missing:
        target.update(status="not measurable", measured="no rows" if mean is None else
                      f"{mean:.2f}; the run has no {', '.join(missing)} rows")
    else:
        target.update(status="met" if mean >= threshold else "missed", measured=f"{mean:.2f} over {len(values)} rows")
    return target


def targets(lines, rows):
    """Issue 33's targets evaluated on the run: a list of {text, status, measured, misses}."""
    out = [
        per_row_target("`bvh8` ≥ 1.05 × `embree`, every row (primary, diffuse, shadow, uniform)", lines,
                       "bvh8_embree", 1.05, RAY_KINDS, "no bvh8 beside embree"),
        per_row_target("`bvh8` ≥ 1.0 × Embree's best, every row (primary, diffuse, shadow, uniform)", lines,
                       "bvh8_best", 1.0, RAY_KINDS, "no bvh8 beside Embree"),
    ]
    traced = [x["best_best"] for x in lines if x["rayset"] in TRACED_KINDS and x["best_best"] is not None]
    missing = [k for k in TRACED_KINDS if not any(x["rayset"] == k for x in lines)]
    out.append(geomean_target("our best ≥ 1.30 × Embree's best, geometric mean over primary, diffuse, shadow", traced,
                              missing, 1.30))
    out.append(per_row_target("our best ≥ 1.10 × Embree's best, every row (primary, diffuse, shadow)", lines,
                              "best_best", 1.10, TRACED_KINDS, "no backend of ours"))
    out.append(per_row_target("watertight ≥ 1.05 × `embree`, every row (primary, diffuse, shadow, uniform)", lines,
                              "wt_embree", 1.05, RAY_KINDS, "no watertight backend of ours beside embree"))
    for threads in (1, 2):
        out.append(build_target(f"default build (`bvh8`) ≤ 1.0 × Embree's medium build, {threads} "
                                f"thread{'s' if threads > 1 else ''}", build_ratios(rows, threads),
                                f"no {threads}-thread rows of bvh8 and embree"))
    return out


def is_our_coherent(backend):
    """A backend of ours in a packet mode: `bvh8:packet`, `bvh8:packet16`, `bvh8:packet:watertight`."""
    return is_ours(backend) and any(p.startswith("packet") for p in backend.split(":")[1:])


def is_embree_coherent(backend):
    """An Embree packet or stream mode, whatever its context flag: `embree:packet8`,
    `embree:high:stream`, `embree:stream:incoherent`, `embree:packet16:incoherent`. The incoherent
    flag is a hint to Embree's traversal, not another kind of ray order; Embree's best coherent
    mode is the fastest of them all."""
    parts = backend.split(":")
    return parts[0] == "embree" and any(m in parts[1:] for m in EMBREE_COHERENT_MODES)


def single_ray_twin(backend):
    """`bvh8:packet` -> `bvh8`: the same backend without its packet option."""
    return ":".join(p for p in backend.split(":") if not p.startswith("packet"))


def coherent_rows_of(rows, threads=1):
    """Per (scene, ray kind) at `threads`, in the run's order: issue 32's ratios. Tiled kinds: our best
    coherent mode against Embree's best coherent mode (`coh_coh`) and against `embree` (`coh_embree`);
    incoherent kinds: the packet backend of ours that loses most against its single-ray twin
    (`packet_single`)."""
    by = {}
    for r in rows:
        if r["threads"] == threads and r["rayset"] in TILED_KINDS + INCOHERENT_KINDS and r["mrays_s"]:
            by.setdefault((r["scene"], r["rayset"]), {})[r["backend"]] = r
    lines = []
    for (scene, kind), backends in by.items():
        ours = [b for b in backends if is_our_coherent(b)]
        if not ours:
            continue
        line = {"scene": scene, "rayset": kind}
        if kind in TILED_KINDS:
            best_name, best = fastest(backends, ours)
            embree_name, embree_best = fastest(backends, [b for b in backends if is_embree_coherent(b)])
            line.update(best=best_name, best_embree=embree_name)
            line["coh_coh"], line["coh_coh_range"] = ratio_with_range(best, embree_best)
            line["coh_embree"], line["coh_embree_range"] = ratio_with_range(best, backends.get("embree"))
        else:
            pairs = [(b, ratio_with_range(backends[b], backends.get(single_ray_twin(b)))) for b in ours]
            pairs = [(b, r) for b, r in pairs if r[0] is not None]
            if not pairs:
                continue
            name, (value, span) = min(pairs, key=lambda p: p[1][0])
            line.update(best=name, single=single_ray_twin(name), packet_single=value, packet_single_range=span)
        lines.append(line)
    return lines


def coherent_targets(lines):
    """Issue 32's targets evaluated on the coherent lines: a list of {text, status, measured, misses}."""
    tiled = [x for x in lines if x["rayset"] in TILED_KINDS]
    out = [per_row_target("our best coherent ≥ 1.30 × Embree's best coherent mode, every row (primary-tiled, "
                          "shadow-tiled)", tiled, "coh_coh", 1.30, TILED_KINDS,
                          "no Embree packet or stream mode beside a packet backend of ours")]
    values = [x["coh_embree"] for x in tiled if x["coh_embree"] is not None]
    missing = [k for k in TILED_KINDS if not any(x["rayset"] == k and x["coh_embree"] is not None for x in tiled)]
    out.append(geomean_target("our best coherent ≥ 2.0 × `embree` (rtcIntersect1), geometric mean over primary-tiled, "
                              "shadow-tiled", values, missing, 2.0))
    out.append(per_row_target("every packet backend of ours ≥ 0.95 × itself without `packet`, every row (diffuse, "
                              "uniform)", [x for x in lines if x["rayset"] in INCOHERENT_KINDS], "packet_single", 0.95,
                              INCOHERENT_KINDS, "no packet backend of ours beside its single-ray twin"))
    return out


def render_coherent(rows):
    """Issue 32's section: the coherent rows, the incoherent ones and the targets; [] for a run
    without a packet backend of ours on the tiled or incoherent rays."""
    lines = coherent_rows_of(rows)
    if not lines:
        return []
    evaluated = coherent_targets(lines)
    met = sum(t["status"] == "met" for t in evaluated)
    out = ["", "## Coherent rays (issue 32)", "",
           "Rays in screen tiles (docs/raysets.md#coherent-orders), one thread. Our best coherent mode is the fastest "
           "backend of ours with a `packet` option, on any of our builds; Embree's the fastest of `embree:packet4/8/16` "
           "and `embree:stream`, on any of its builds (e.g. `embree:high:packet16`), with the coherent or the "
           "incoherent flag (`:incoherent`).",
           "", "| scene | ray kind | our best coherent | Embree's best coherent | ours / Embree's best coherent "
           "| ours / `embree` |", "|---|---|---|---|---:|---:|"]
    for x in lines:
        if x["rayset"] in TILED_KINDS:
            out.append(f"| {x['scene']} | {x['rayset']} | {x['best']} | {x['best_embree'] or '-'} | "
                       f"{fmt_ratio(x['coh_coh'], x['coh_coh_range'])} | "
                       f"{fmt_ratio(x['coh_embree'], x['coh_embree_range'])} |")
    incoherent = [x for x in lines if x["rayset"] in INCOHERENT_KINDS]
    if incoherent:
        out += ["", "On incoherent rays a packet backend falls back to single rays: its rate against the same "
                "backend without `packet` (the packet backend that loses most, per row).", "",
                "| scene | ray kind | packet backend | / single-ray |", "|---|---|---|---:|"]
        for x in incoherent:
            out.append(f"| {x['scene']} | {x['rayset']} | {x['best']} / {x['single']} | "
                       f"{fmt_ratio(x['packet_single'], x['packet_single_range'])} |")
    out += ["", f"### Issue 32's targets: {met} of {len(evaluated)} met", "", "| target | measured | |",
            "|---|---|---|"]
    out += [f"| {t['text']} | {t['measured']} | **{t['status']}** |" for t in evaluated]
    missed = [t for t in evaluated if t["misses"]]
    if missed:
        out += ["", "Rows below their target:"]
        out += [f"- {t['text']}: " + "; ".join(t["misses"]) + "." for t in missed]
    return out


def summary(meta, lines, evaluated, source):
    """The facts of the index line of this scorecard."""
    traced = [x["best_best"] for x in lines if x["rayset"] in TRACED_KINDS and x["best_best"] is not None]
    bvh8 = [x["bvh8_embree"] for x in lines if x["bvh8_embree"] is not None]
    mean, bvh8_mean = geometric_mean(traced), geometric_mean(bvh8)
    return {"class": machine_class(meta), "cpu": str(meta.get("cpu", "")), "isa": cpu_isa(meta) or "",
            "date": str(meta.get("date", ""))[:10], "commit": str(meta.get("git_commit", meta.get("commit", "")))[:7],
            "run": os.path.basename(source),
            "best_geomean": None if mean is None else round(mean, 2),
            "bvh8_geomean": None if bvh8_mean is None else round(bvh8_mean, 2),
            "met": sum(t["status"] == "met" for t in evaluated), "targets": len(evaluated),
            "missing_scenes": len(missing_suite_scenes(meta)),
            "not_measurable": sum(t["status"] == "not measurable" for t in evaluated),
            "old_embree_loop": not embree_provenance(meta)}


DEFAULT_SUITE = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "meshes", "default.toml")


def missing_suite_scenes(meta, suite=DEFAULT_SUITE):
    """The scenes of today's default suite that a run of the default suite (its metadata's `suite`)
    did not trace: a suite grown since the run. [] for a run of another suite."""
    if not str(meta.get("suite", "")).endswith("default.toml") or not os.path.exists(suite):
        return []
    with open(suite, "rb") as f:
        names = [s.get("name") for s in tomllib.load(f).get("scene", [])]
    ran = set(str(meta.get("scenes", "")).split(","))
    return [n for n in names if n and n not in ran]


def header(meta, source, subject="our BVHs against Embree (issue 33)"):
    """The scorecard's opening: the machine class, the CPU and its ISA, the build, Embree's configuration."""
    cls = machine_class(meta)
    isa = cpu_isa(meta)
    out = [f"# Scorecard of machine class {cls}: {subject}", "",
           f"From `{os.path.basename(source)}`, one thread unless said, ratios within the run.", "",
           f"CPU: {meta.get('cpu', 'not recorded')} ({meta.get('cpu_id', 'cpu_id not recorded')}); "
           f"ISA: {isa or 'not recorded'}; built with {meta.get('compiler', 'an unrecorded compiler')}, "
           f"`{meta.get('flags', 'flags not recorded')}`."]
    run = [f"{k}: {meta[k]}" for k in ("date", "git_commit", "host", "threads", "repetitions") if k in meta]
    if run:
        out.append("Run: " + "; ".join(run) + ".")
    missing = missing_suite_scenes(meta)
    if missing:
        out.append(f"The run lacks {len(missing)} of the default suite's scenes as it stands now: {', '.join(missing)}.")
    facts = embree_config(meta)
    out.append(f"Embree {meta.get('embree', '(version not recorded)')}: " +
               "; ".join(f"{fact} {value}" for fact, value in facts.items()) + ".")
    if not embree_provenance(meta):
        out.append(PREDATES_EMBREE_FIX)
    return out


def render(rows, meta, source, plot=None):
    """Issue 33's scorecard of one run, in Markdown, ending with its summary comment."""
    lines = rows_of(rows)
    evaluated = targets(lines, rows)
    out = header(meta, source)
    out += ["", "| scene | ray kind | bvh8 / embree | bvh8 / Embree's best | our best | our best / Embree's best "
            "| watertight / embree |", "|---|---|---:|---:|---|---:|---:|"]
    for x in lines:
        out.append(f"| {x['scene']} | {x['rayset']} | {fmt_ratio(x['bvh8_embree'], x['bvh8_embree_range'])} | "
                   f"{fmt_ratio(x['bvh8_best'], x['bvh8_best_range'])} | {x['best']} | "
                   f"{fmt_ratio(x['best_best'], x['best_best_range'])} | {fmt_ratio(x['wt_embree'], x['wt_embree_range'])} |")
    out += ["", range_sentence(rows) + ". \"Within noise\": a row below its target whose range reaches it."]
    noise = run_noise(rows, kinds=RAY_KINDS)
    if noise:
        out += ["", noise]
    builds = {t: build_ratios(rows, t) for t in (1, 2)}
    if builds[1]:
        two = dict((s, (v, span)) for s, v, span in builds[2])
        out += ["", "| scene | build / embree medium, 1 thread | 2 threads |", "|---|---:|---:|"]
        for scene, value, span in builds[1]:
            out.append(f"| {scene} | {fmt_ratio(value, span)} | {fmt_ratio(*two.get(scene, (None, None)))} |")
    met = sum(t["status"] == "met" for t in evaluated)
    out += ["", f"## Issue 33's targets: {met} of {len(evaluated)} met", "", "| target | measured | |", "|---|---|---|"]
    for t in evaluated:
        out.append(f"| {t['text']} | {t['measured']} | **{t['status']}** |")
    missed = [t for t in evaluated if t["misses"]]
    if missed:
        out += ["", "Rows below their target:"]
        for t in missed:
            out.append(f"- {t['text']}: " + "; ".join(t["misses"]) + ".")
    if plot:
        out += ["", f"![bvh8 against embree and our best against Embree's best, per scene and ray kind]({plot})"]
    out += render_coherent(rows)
    return out, summary(meta, lines, evaluated, source)


COHERENT_PANELS = (("coh_coh", "coh_coh_range", "ours / Embree's best coherent", 1.30),
                   ("coh_embree", "coh_embree_range", "ours / embree", 2.0),
                   ("packet_single", "packet_single_range", "packet / single-ray", 0.95))


def coherent_plot_lines(rows):
    """The coherent lines with every panel's key (None where a kind has no such ratio), for the plot."""
    lines = coherent_rows_of(rows)
    for x in lines:
        for key, range_key, _, _ in COHERENT_PANELS:
            x.setdefault(key, None)
            x.setdefault(range_key, None)
    return lines


def render_coherent_card(rows, meta, source, plot=None):
    """The coherent scorecard of a coherent run (meshes/coherent.toml): the header and issue 32's
    section alone, in Markdown lines."""
    out = header(meta, source, "coherent rays, our packets against Embree's packets and streams (issue 32)")
    if plot:
        out += ["", f"![ours against Embree's best coherent mode and against embree, per scene and ray kind]({plot})"]
    return out + render_coherent(rows) + ["", range_sentence(rows, "the row compared with") + "."]


def summary_comment(facts):
    return SUMMARY_MARK + json.dumps(facts, sort_keys=True) + " -->"


def read_summary(path):
    """The summary comment of a scorecard written by render, or None (a file of another kind)."""
    with open(path, encoding="utf-8") as f:
        for line in f:
            if line.startswith(SUMMARY_MARK):
                try:
                    return json.loads(line[len(SUMMARY_MARK):].rsplit("-->", 1)[0])
                except json.JSONDecodeError as e:
                    raise InputError(path, f"unreadable scorecard summary: {e}")
    return None


def index_lines(directory, link_prefix=""):
    """The index table's Markdown lines, one per scorecard in `directory`, by machine class; links
    prefixed by `link_prefix` (the directory as seen from where the lines go: the README's headline)."""
    cards = []
    for name in sorted(os.listdir(directory)):
        if name.endswith(".md") and name != "README.md":
            facts = read_summary(os.path.join(directory, name))
            if facts:
                cards.append((name, facts))
    out = ["| machine class | CPU | ISA | run | commit | our best / Embree's best (geo. mean) | bvh8 / embree (geo. mean) "
           "| issue 33's targets met |", "|---|---|---|---|---|---:|---:|---|"]
    for name, f in cards:
        unmeasurable = f", {f['not_measurable']} not measurable" if f.get("not_measurable") else ""
        if f.get("missing_scenes"):
            unmeasurable += f"; the run lacks {f['missing_scenes']} of today's default-suite scenes"
        if f.get("old_embree_loop"):
            unmeasurable += "; measured before issue 33's Embree wrapper fix (its ratios overstate ours)"
        fmt = lambda v: "-" if v is None else f"{v:.2f}"  # noqa: E731
        out.append(f"| [{f['class']}]({link_prefix}{name}) | {f['cpu']} | {f['isa']} | {f['date']} | `{f['commit']}` | "
                   f"{fmt(f['best_geomean'])} | {fmt(f['bvh8_geomean'])} | {f['met']} of {f['targets']}{unmeasurable} |")
    return out, len(cards)


def write_index(directory):
    """results/scorecards/README.md: every machine class's scorecard in one table."""
    table, count = index_lines(directory)
    text = ["# Scorecards per machine class", "",
            "One scorecard per CPU vendor, family and model (issue 33), each made by `scripts/bvh-scorecard` from the "
            "full run committed beside it (`<class>-run.csv`, `.meta.toml`); this index is generated from them "
            "(`scripts/bvh-scorecard --index results/scorecards`). Geometric means of our best over the primary, "
            "diffuse and shadow rows and of the default `bvh8` over every ray kind, one thread. How to make one: "
            "[docs/method.md](../../docs/method.md#the-bvh-scorecard).", ""] + table
    if count == 0:
        text.append("")
        text.append("No scorecard yet.")
    coherent = sorted(n for n in os.listdir(directory) if n.endswith("-coherent.md"))
    if coherent:
        text += ["", "Coherent rays (issue 32: our packets against Embree's packets and streams, from a run of "
                 "`meshes/coherent.toml`, `scripts/bvh-scorecard RUN.csv --targets issue32 --machine-dir "
                 "results/scorecards`): " + ", ".join(f"[{n[:-len('-coherent.md')]}]({n})" for n in coherent) + "."]
    with open(os.path.join(directory, "README.md"), "w", encoding="utf-8") as f:
        f.write("\n".join(text) + "\n")
    return count
