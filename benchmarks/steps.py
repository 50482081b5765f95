"""The plan of ``benchmarks/run.py``: every result generator of benchmarks/ as a step, and what
every other script and every result file not written by a step is.

A **step** runs one script in a fresh process with fixed arguments and names what it writes
(relative to ``benchmarks/``, or to ``run.py --out DIR``).  Its ``group`` lets ``run.py --only``
take a whole group (``--only solid``).  ``quick`` are the arguments of its quick mode (a smaller
problem, about a minute at most, whose files carry ``-quick``), or None where there is none that
small: the step is then left out of ``run.py --quick``.  ``out`` says how the step is told
where to write:

* ``"dir"``: the script takes ``--out-dir DIR`` (results/ and figures/ under DIR;
  ``checkout.add_output_args``), passed only with ``run.py --out``;
* ``(flag, path)``: the script takes an output path; ``path`` (with ``{q}`` for ``-quick``) is
  passed under ``benchmarks/`` or ``--out DIR`` every time;
* None: the script writes into benchmarks/ only; with ``--out`` the step is left out (said so
  by ``run.py --list``) rather than writing into the checkout.

``needs``: a module the full run needs (numba); without it the step is skipped, and said so.
``cost`` is the step's full run in seconds on the shared 2-core machine, from its result file
(``source`` "stated": the time the file gives for the whole run; "sum": the sum of the per-case
times the file gives) or None where the file gives none.
"""

from __future__ import annotations

import re
from pathlib import Path

HERE = Path(__file__).resolve().parent

GROUPS = ("precision", "speed", "model", "stability", "solid", "fits", "trust", "figures")


class Step:
    def __init__(self, name, script, group, full=(), quick=None, outputs=(), quick_outputs=None, out="dir",
                 cost=None, source=None, optional=False, needs=None, note=""):
        assert group in GROUPS, group
        self.name, self.script, self.group = name, script, group
        self.full, self.quick = list(full), (None if quick is None else list(quick))
        self.outputs = tuple(outputs)
        self.quick_outputs = tuple(quick_outputs) if quick_outputs is not None else (
            tuple(_quick_name(o) for o in outputs) if quick is not None else ())
        self.out, self.cost, self.source = out, cost, source
        self.optional, self.needs, self.note = optional, needs, note

    def argv(self, quick, out, python):
        """The command line, or None where this mode is not run (no quick mode; ``--out`` given
        to a step that cannot write elsewhere)."""
        args = self.quick if quick else self.full
        if args is None or (self.out is None and out is not None):
            return None
        args = list(args)
        if self.out == "dir":
            if out is not None:
                args += ["--out-dir", str(out)]
        elif self.out is not None:
            flag, path = self.out
            args += [flag, str(Path(out if out is not None else HERE) / path.format(q="-quick" if quick else ""))]
        return [python, str(HERE / self.script)] + args


def _quick_name(path):
    """``results/x.json`` -> ``results/x-quick.json``."""
    head, _, name = path.rpartition("/")
    stem, dot, ext = name.partition(".")
    return f"{head}/{stem}-quick{dot}{ext}" if head else f"{stem}-quick{dot}{ext}"


def _r(*names, ext=("json", "md")):
    return [f"results/{n}.{e}" for n in names for e in ext]


#: trust_tally.py's kinds whose quick mode takes seconds (62 s for all of them, under load)
QUICK_KINDS = "formulas,hdf5,csv,scenes,cli,fitrecords,sweepfiles,inputs,options"

FIGURES = ("beta_xi", "rho", "gamma", "material", "profiles", "hemisphere_beta01", "fit")

STEPS = (
    # -- precision: error against time, the shooting peer, the error estimates
    Step("work_precision", "work_precision.py", "precision", [], ["--quick"],
         _r("work_precision") + ["results/work_precision-summary.md", "figures/work_precision.png"],
         _r("work_precision-quick") + ["results/work_precision-quick-summary.md", "figures/work_precision-quick.png"],
         cost=1897, source="stated"),
    Step("shooting", "shooting.py", "precision", [], None, _r("shooting"), out=("--out", "results/shooting{q}.json"),
         note="its quick mode still needs 10-20 s cold starts per state: left out of --quick"),
    Step("error_estimates", "error_estimates.py", "precision", [], None, _r("error_estimates"), cost=1200,
         source="stated", note="~20 min (its docstring)"),
    # -- speed: where the time goes, against the baseline, whole commands, maps and sweeps
    Step("profile", "profile_hot_path.py", "speed", [], ["--quick"], _r("profile")),
    Step("point_budget", "point_budget.py", "speed", [], ["--quick"], _r("point_budget"), needs="numba",
         note="the full run's numba rows need numba (pip install 'shellbvp[fast]'); its quick mode does not"),
    Step("codegen_timing", "codegen_timing.py", "speed", ["--repeat", "3"], ["--quick"], _r("codegen")),
    Step("kernels", "kernels.py", "speed", [], ["--quick"], _r("kernels"),
         note="without numba the script says so and writes nothing"),
    Step("speed_vs_baseline", "speed_vs_baseline.py", "speed", [], ["--quick"], _r("speed_vs_baseline"),
         cost=766, source="stated"),
    Step("commands", "commands.py", "speed", [], None, _r("commands"), cost=528, source="stated"),
    Step("map_scaling", "map_scaling.py", "speed", [], None, _r("map_scaling"), cost=156, source="sum"),
    Step("map_scaling_large", "map_scaling.py", "speed", ["--large"], None, _r("map_scaling-large"),
         cost=660, source="sum"),
    Step("sweep_scaling", "sweep_scaling.py", "speed", [], ["--quick"], _r("sweep_scaling")),
    Step("sweep_kill_resume", "sweep_kill_resume.py", "speed", [], None, _r("sweep_kill_resume")),
    # -- model: states, curves, configurations and switches on the presets
    Step("states_table", "states_table.py", "model", [], ["--quick"], _r("states"), cost=20, source="sum"),
    Step("preset_curves", "preset_curves.py", "model", [], ["--quick"], _r("preset_curves"), cost=44, source="sum"),
    Step("topologies", "topologies.py", "model", [], ["--quick"], _r("topologies")),
    Step("configurations", "configurations.py", "model", [], ["--quick"], ["results/configurations.md"],
         cost=34, source="stated"),
    Step("corner_switches", "corner_switches.py", "model", [], ["--quick"], ["results/corner_switches.md"],
         cost=147, source="stated"),
    Step("bending_choice", "bending_choice.py", "model", [], None, ["results/bending_choice.md"],
         cost=209, source="stated"),
    Step("bending_koiter", "bending_choice.py", "model", ["--koiter"], None, ["results/bending_koiter.md"],
         cost=951, source="stated"),
    Step("bending_koiter_map", "bending_choice.py", "model", ["--koiter-map"], None, _r("bending_koiter_map"),
         note="the shell side only, against the solids kept in benchmarks/results/validation.json (read there "
              "under --out too)"),
    Step("vella", "vella.py", "model", [], ["--quick"], _r("vella")),
    # -- stability
    Step("stability", "stability.py", "stability", [], ["--quick", "--only", "^base$"], _r("stability"),
         cost=311, source="stated"),
    Step("stability_numba", "stability.py", "stability", ["--kernels", "numba", "--out", "stability-numba"], None,
         _r("stability-numba"), cost=90, source="stated", needs="numba"),
    Step("stability_modes", "stability_modes.py", "stability", [], ["--quick"], _r("stability_modes"),
         cost=244, source="stated"),
    Step("hoop_indicator", "hoop_indicator.py", "stability", [], ["--quick"], _r("hoop_indicator"),
         cost=946, source="stated"),
    Step("stability_friction", "stability_friction.py", "stability", [], ["--quick"], _r("stability_friction"),
         cost=32, source="stated"),
    Step("stability_contact", "stability_contact.py", "stability", [], None, _r("stability_contact"),
         cost=311, source="stated"),
    Step("stability_pressure", "stability_pressure.py", "stability", [], None, _r("stability_pressure")),
    # -- solid: the 3D reference, the shell against it, fits of its records
    Step("validation", "validation.py", "solid", [], None, _r("validation"), cost=7362, source="sum",
         note="FE curves are kept in its JSON: into an empty --out DIR every one is computed again"),
    Step("validation_table", "validation_table.py", "solid", [], ["--quick"], _r("validation_table"),
         cost=293, source="sum"),
    Step("fe_convergence", "fe_convergence.py", "solid", [], None, _r("fe_convergence"), cost=1299, source="sum",
         note="the committed .md is the table of a run whose JSON was not kept (its --finest run was stopped); "
              "docs/accuracy.md quotes it"),
    Step("fe_speed", "fe_speed.py", "solid", [], ["--quick"], _r("fe_speed"), cost=106, source="sum"),
    Step("fe_speed_thin", "fe_speed.py", "solid", ["--thin", "--only", "0.01", "0.02", "--tag", "thin"], None,
         _r("fe_speed-thin"), cost=1300, source="sum"),
    Step("indenter_displacement", "indenter_displacement.py", "solid", [], None, _r("indenter_displacement"),
         out=("--out", "results/indenter_displacement{q}"), cost=32, source="stated"),
    Step("thick_fits", "thick_fits.py", "solid", ["--timing"], None, _r("thick_fits"), cost=549, source="stated",
         note="the stated time is the fits' and the convergence's; the timed commands add ~60 s"),
    # the map's scenes: the committed files fitted the records their earlier runs kept (--records: made at 220e928);
    # the steps make them again, which the solid takes 334 s (eps 0.05) and 3,376 s (0.02) of CPU for
    Step("thick_fits_mapped_eps0.05", "thick_fits.py", "solid", ["--set", "mapped", "--eps", "0.05",
                                                                  "--no-convergence"], None,
         _r("thick_fits_mapped_eps0.05"), cost=381, source="stated",
         note="the committed file fitted kept records (--records): the records' 334 s CPU not in its time"),
    Step("thick_fits_mapped_eps0.02", "thick_fits.py", "solid", ["--set", "mapped", "--eps", "0.02",
                                                                  "--no-convergence"], None,
         _r("thick_fits_mapped_eps0.02"), cost=1276, source="stated",
         note="the committed file fitted kept records (--records): the records' 3,376 s CPU not in its time"),
    # Koiter's energy on the same records (the solid's do not depend on the shell's energy): a bare --records name
    # is read from the results folder the step writes to, where the step before wrote it
    Step("thick_fits_koiter", "thick_fits.py", "solid", ["--bending", "koiter", "--no-convergence"], None,
         _r("thick_fits_koiter"), cost=442, source="stated"),
    Step("thick_fits_mapped_eps0.05_koiter", "thick_fits.py", "solid",
         ["--set", "mapped", "--eps", "0.05", "--no-convergence", "--bending", "koiter",
          "--records", "thick_fits_mapped_eps0.05.json"], None,
         _r("thick_fits_mapped_eps0.05_koiter"), cost=367, source="stated",
         note="fits the records kept in thick_fits_mapped_eps0.05.json"),
    Step("thick_fits_mapped_eps0.02_koiter", "thick_fits.py", "solid",
         ["--set", "mapped", "--eps", "0.02", "--no-convergence", "--bending", "koiter",
          "--records", "thick_fits_mapped_eps0.02.json"], None,
         _r("thick_fits_mapped_eps0.02_koiter"), cost=106, source="stated",
         note="fits the records kept in thick_fits_mapped_eps0.02.json"),
    Step("thick_fits_closed", "thick_fits.py", "solid", ["--set", "closed", "--no-convergence", "--timing"], None,
         _r("thick_fits_closed"), cost=224, source="stated"),
    Step("thick_fits_closed-mapped_eps0.05", "thick_fits.py", "solid", ["--set", "closed-mapped", "--eps", "0.05"],
         None, _r("thick_fits_closed-mapped_eps0.05"), cost=3837, source="stated",
         note="its records' solids 2,228 s (the file states them) and the cold fits 1,609 s over two runs; "
              "a rerun fits the kept records again"),
    Step("thick_fits_closed-mapped_eps0.02", "thick_fits.py", "solid", ["--set", "closed-mapped", "--eps", "0.02"],
         None, _r("thick_fits_closed-mapped_eps0.02"), cost=1782, source="stated",
         note="its record's solid 1,722 s (the file states it), the cold fits 60 s"),
    Step("thick_fits_closed_check", "thick_fits.py", "solid", ["--closed-map-check"], None,
         _r("thick_fits_closed_check"), note="reads thick_fits_closed.json and the package's closed map"),
    Step("profile_solid", "profile_solid.py", "solid", [], ["--quick"], _r("profile_solid"), cost=653, source="sum",
         note="quick: two walls to delta = H0 without the mesh check: 21 s CPU, 41-91 s wall at load 13-14"),
    Step("closed_solid", "closed_solid.py", "solid", ["--sealed"], None, _r("closed_solid"), cost=1346, source="sum",
         note="FE curves are kept in its JSON: into an empty --out DIR every one is computed again"),
    # -- fits: interval coverage, the models' checks, the contact estimate
    Step("fit_coverage", "fit_coverage.py", "fits", [], ["--quick"], _r("fit_coverage"), cost=439, source="stated"),
    Step("fit_baseline_coverage", "fit_baseline_coverage.py", "fits", [], ["--quick"],
         ["results/fit_baseline_coverage.md"]),
    Step("closed_matrix", "closed_matrix.py", "fits", [], ["--quick"], _r("closed_matrix", ext=("md",)), cost=869,
         source="stated"),
    Step("fit_models", "fit_models.py", "fits", [], None, _r("fit_models"), cost=52, source="stated",
         note="52 s with the claims' curves memoised in the temporary directory; without them longer"),
    Step("weights_check_rate", "weights_check_rate.py", "fits", [], None, _r("weights_check_rate"),
         cost=764, source="stated"),
    Step("contact_estimate", "contact_estimate.py", "fits",
         ["--records", "2000", "--fits", "10", "--afm-dir", "tests/data/afm"],
         ["--quick", "--afm-dir", "tests/data/afm"],
         ["results/contact_estimate.md"],
         note="the AFM files the repository ships (tests/data/afm); the committed file was made on all of afmformats' "
              "test files and with --against (an older checkout)"),
    Step("profile_fit", "profile_fit.py", "fits", [], None, ["results/profile_fit.md"],
         out=("--out", "results/profile_fit{q}.md")),
    # -- trust: hostile and malformed input (trust_tally.py and its kinds)
    Step("trust_tally", "trust_tally.py", "trust", [], ["--quick", "--only", QUICK_KINDS], ["results/trust_tally.md"],
         out=("--out", "results/trust_tally{q}.md"), cost=1461, source="stated",
         note="quick: the kinds that take seconds (the cache, full disk, work and AFM kinds take minutes even so)"),
    Step("trust_work", "trust_tally.py", "trust", ["--only", "options,work"], None, ["results/trust_work.md"],
         out=("--out", "results/trust_work{q}.md"), cost=158, source="stated"),
    Step("trust_afm", "trust_tally.py", "trust", ["--only", "afmdamaged,afmsizes"], None, ["results/trust_afm.md"],
         out=("--out", "results/trust_afm{q}.md"), cost=117, source="stated"),
    Step("trust_cache", "trust_tally.py", "trust", ["--only", "keptcurves,cachefolders,kernels,fulldisk"], None,
         ["results/trust_cache.md"], out=("--out", "results/trust_cache{q}.md"), cost=507, source="stated"),
    # -- figures (only with run.py --figures or --only)
    Step("paper_figures", "paper_figures.py", "figures", [], None, [f"figures/{f}.png" for f in FIGURES],
         optional=True),
)

#: Scripts of benchmarks/ that are not steps, and why.
TOOLS = {
    "run.py": "the driver: runs the steps",
    "steps.py": "the plan (this module)",
    "checkout.py": "a library: the checkout's environment and commit label, where a step writes",
    "architecture.py": "the census of the package's source, asserted by tests/test_benchmarks.py; "
                       "results/architecture.md is its --markdown table inside prose kept by hand",
    "same_curves.py": "compares this checkout's curves with another commit's (--against COMMIT); "
                      "its answer is the exit status, no result file",
    "make_example_data.py": "writes the records shipped in shellbvp/data/ (--write) or the same files elsewhere "
                            "(--out-dir), not a result; tests/test_benchmark_scripts.py compares them",
    "make_force_map.py": "writes a synthetic JPK map (for commands.py, map_scaling.py and users)",
    "make_instrument_examples.py": "writes example records into a folder (docs/fitting.md's batch example)",
    "regression_reference.py": "writes tests/data/regression_states.json (--out, --overwrite), run at commit 1109cdf: "
                               "run here it would compare the code with itself",
    "trust_afm.py": "kinds 13-14 of trust_tally.py (steps trust_tally, trust_afm)",
    "trust_cache.py": "kinds 9-12 of trust_tally.py (steps trust_tally, trust_cache)",
    "trust_work.py": "kinds 15-16 of trust_tally.py (steps trust_tally, trust_work)",
}

#: Files in results/ that no step writes, and why they are kept (glob patterns).
RECORDS = {
    "architecture.md": "architecture.py --markdown's table inside prose kept by hand",
    "stability_literature.md": "published numbers with their sources, written by hand",
    "commands-force-map.*": "commands.py --only 'force map' at 88cc949; the commands step's table holds these rows",
    "contact_estimate-before.md": "contact_estimate.py with the package of an earlier commit",
    "fe_speed-before.*": "fe_speed.py at bce31dc's parent (issue 54, item 5), for comparison",
    "fe_speed-after.*": "fe_speed.py at bce31dc against -before (issue 54, item 5)",
    "fe_speed-old-alt.*": "fe_speed.py with other FE settings (--set), for comparison",
    "fe_speed-new-grow.*": "fe_speed.py with other FE settings (--set), for comparison",
    "fit_coverage-before.*": "fit_coverage.py --approach-only --tag before with another checkout's package",
    "suite_cost.md": "the test suite's CPU per test (pytest with a local timing plugin over two full runs), written by hand",
}

#: What run.py itself writes into results/ (its summary of a run)
DRIVER = ("run.json", "run-quick.json")


def select(only=None):
    """The steps named by ``only`` (step or group names), in plan order; ValueError for unknown names."""
    if not only:
        return list(STEPS)
    names = {s.name for s in STEPS}
    unknown = set(only) - names - set(GROUPS)
    if unknown:
        raise ValueError(f"unknown steps {sorted(unknown)}; choose from the groups {list(GROUPS)} "
                         f"or the steps {sorted(names)}")
    return [s for s in STEPS if s.name in only or s.group in only]


def claimed(path_name):
    """Whether a file of results/ is written by a step (either mode) or kept as a record."""
    pats = [o.split("/", 1)[1] for s in STEPS for o in s.outputs + s.quick_outputs if o.startswith("results/")]
    pats += list(RECORDS) + list(DRIVER)
    return any(re.fullmatch(re.escape(p).replace(r"\*", ".*"), path_name) for p in pats)
