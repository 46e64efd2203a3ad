# Figure 4's claims as statistics over piles of three construction histories.
#   construct  the three piles of member m (n grains), point, rain, then layer (its rain
#              falls over the point pile's base width); one job per member, so that its
#              start-up is paid once; checkpoints in results/fig4_history/checkpoints (resumed
#              after a kill, removed at the end)              -> piles/n<n>/<history>_<m>.nc
#   exact      exact angle ranges over A ∩ C at the arching cuts of the first exact.piles
#              members of the point and rain histories (exact.solver: HiGHS's simplex, or Clarabel's
#              interior point for 10^4 grains; ncd.figures.fig4_history.exact), both
#              histories of a member in one job                 -> exact/n<n>/<history>_<m>.nc
#   analyse    shape match, ground stress, dip, arching over the piles, the comparison
#              of the histories and its controls                -> analysis_n<n>.nc
#   notebook   notebooks/fig4_history.ipynb                     -> results/figures/fig4_history.png|pdf
# Size study (target fig4_history_size, not in the default run): the piles of this config and
# of every overlay in fig4_history.size.overlays (a config file whose fig4_history section is
# merged over this one, e.g. config/large.yaml: 10^4 grains), each analysed as above
#   size       the analyses side by side                        -> size.nc
#   notebook   notebooks/fig4_history_size.ipynb                -> results/figures/fig4_history_size.png|pdf
import copy as _copy

import yaml as _yaml
from snakemake.utils import update_config as _update_config

FIGH = "fig4_history"
CFGH = section(FIGH)
FH = f"results/{FIGH}"
NH = CFGH["grains"]["n"]
# the construction sees only what builds a pile (an analysis parameter does not rebuild the piles)
SIM_KEYS = ("root_seed", "grains", "ground", "mu", "mu_ground", "gravity", "h", "source", "rain", "layer",
            "construction", "surface")


def _size_sections():
    """{n: fig4_history section} for this config and each size overlay, checked like the config."""
    out = {NH: CFGH}
    for path in CFGH.get("size", {}).get("overlays", []):
        with open(REL / path) as f:
            over = (_yaml.safe_load(f) or {}).get(FIGH)
        if not isinstance(over, dict):
            raise ValueError(f"fig4_history.size.overlays: {path} has no fig4_history section")
        sec = _copy.deepcopy(CFGH)
        _update_config(sec, over)
        check_config({FIGH: sec}, [FIGH], ROOT / "workflow" / "schemas")
        out.setdefault(int(sec["grains"]["n"]), sec)
    return out


SIZE_CFG = _size_sections()
SIZES = sorted(SIZE_CFG)


def size_cfg(n):
    """The fig4_history section that builds piles of ``n`` grains."""
    if int(n) not in SIZE_CFG:
        raise ValueError(f"no fig4_history config builds piles of n = {n} grains (sizes: {SIZES})")
    return SIZE_CFG[int(n)]


HISTORIES_H = ("point", "rain", "layer")     # ncd.figures.fig4_history.construct.HISTORIES
EXACT_HISTORIES = ("point", "rain")          # the heaps compared at matched shape


def piles_of(n):
    c = size_cfg(n)
    return [f"{FH}/piles/n{n}/{h}_{m:03d}.nc" for h in HISTORIES_H for m in range(c["piles"])]


def exact_of(n):
    c = size_cfg(n)
    return [f"{FH}/exact/n{n}/{h}_{m:03d}.nc" for h in EXACT_HISTORIES
            for m in range(min(c["exact"]["piles"], c["piles"]))]


FH_PILES = piles_of(NH)
FH_EXACT = exact_of(NH)


rule fig4_history_construct:
    input:
        code=code_of("fig4_history_construct"),
    output:
        **{h: f"{FH}/piles/n{{n}}/{h}_{{member}}.nc" for h in HISTORIES_H},
    wildcard_constraints:
        member=r"\d+",
        n=r"\d+",
    params:
        config=lambda w: {k: size_cfg(w.n)[k] for k in SIM_KEYS},
        checkpoints=lambda w: {h: f"{FH}/checkpoints/n{w.n}/{h}_{w.member}.npz" for h in HISTORIES_H},
    log:
        log(FIGH, "construct_n{n}_{member}"),
    benchmark:
        bench(FIGH, "construct_n{n}_{member}")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig4_history_construct.py"


rule fig4_history_exact:
    input:
        **{h: f"{FH}/piles/n{{n}}/{h}_{{member}}.nc" for h in EXACT_HISTORIES},
        code=code_of("fig4_history_exact"),
    output:
        **{h: f"{FH}/exact/n{{n}}/{h}_{{member}}.nc" for h in EXACT_HISTORIES},
    wildcard_constraints:
        member=r"\d+",
        n=r"\d+",
    params:
        config=lambda w: {k: v for k, v in size_cfg(w.n).items() if k not in ("piles", "size")},   # one pile's ranges
    log:
        log(FIGH, "exact_n{n}_{member}"),
    benchmark:
        bench(FIGH, "exact_n{n}_{member}")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig4_history_exact.py"


rule fig4_history_analyse:
    input:
        piles=lambda w: piles_of(w.n),
        exact=lambda w: exact_of(w.n),
        code=code_of("fig4_history_analyse"),
    output:
        f"{FH}/analysis_n{{n}}.nc",
    wildcard_constraints:
        n=r"\d+",
    params:
        config=lambda w: {k: v for k, v in size_cfg(w.n).items() if k != "size"},
    log:
        log(FIGH, "analyse_n{n}"),
    benchmark:
        bench(FIGH, "analyse_n{n}")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig4_history_analyse.py"


rule fig4_history_notebook:
    input:
        analysis=f"{FH}/analysis_n{NH}.nc",
        point=f"{FH}/piles/n{NH}/point_000.nc",
        rain=f"{FH}/piles/n{NH}/rain_000.nc",
        layer=f"{FH}/piles/n{NH}/layer_000.nc",
        notebook=notebook_file(FIGH),
        notebook_py=notebook_file(FIGH, "py"),
        code=notebook_code("fig4_history"),
    output:
        png=figure_output(FIGH, "png"),
        pdf=figure_output(FIGH, "pdf"),
        finding=f"results/figures/{FIGH}.finding.rst",   # included by the report's caption
    params:
        config=CFGH,
    log:
        notebook=f"results/notebooks/{FIGH}.ipynb",
    benchmark:
        bench(FIGH, "notebook")
    conda:
        CONDA_ENV
    notebook:
        "../../notebooks/fig4_history.ipynb"


rule fig4_history:
    input:
        figure_targets(FIGH),


FHS = "fig4_history_size"


rule fig4_history_size_analyse:
    """The analyses of every pile size side by side (ncd.figures.fig4_history.size)."""
    input:
        analyses=[f"{FH}/analysis_n{n}.nc" for n in SIZES],
        code=code_of("fig4_history_size"),
    output:
        f"{FH}/size.nc",
    params:
        seed=CFGH["analysis"]["seed"],
    log:
        log(FIGH, "size"),
    benchmark:
        bench(FIGH, "size")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig4_history_size.py"


rule fig4_history_size_notebook:
    input:
        sizes=f"{FH}/size.nc",
        notebook=notebook_file(FHS),
        notebook_py=notebook_file(FHS, "py"),
        code=notebook_code("fig4_history_size"),
    output:
        png=figure_output(FHS, "png"),
        pdf=figure_output(FHS, "pdf"),
        finding=f"results/figures/{FHS}.finding.rst",   # included by the report's caption
    params:
        config={k: v for k, v in CFGH.items() if k == "size"},
    log:
        notebook=f"results/notebooks/{FHS}.ipynb",
    benchmark:
        bench(FHS, "notebook")
    conda:
        CONDA_ENV
    notebook:
        "../../notebooks/fig4_history_size.ipynb"


rule fig4_history_size:
    """The size study: piles of every size, their analyses and the comparison page (the
    longest target: config/large.yaml's four piles of 10^4 grains per history and their
    exact ranges; once it has run, the bench page lists each job's time and the exact sets'
    LP time)."""
    input:
        figure_targets(FHS),
