# Figure 5: what governs indeterminacy — static packings across friction in Unger, Kertész &
# Wolf's geometry (two plates, the top one mobile, no gravity), a middle slice measured exactly
# (LPs on A ∩ C), sampled by their random walk and uniformly (hit-and-run).
#   pack      builds of one shard by contact dynamics           -> shards/packs_<k>-of-<n>.nc
#   analyse   analyses of one shard (every build read)          -> shards/analyses_<k>-of-<n>.nc
#   merge     every shard of both                               -> packings.nc
#   deposit, flow, flows (below): Figure 2's flow across mu, h, slope  -> flows.nc
#   notebook  notebooks/fig5_governing.ipynb                    -> results/figures/fig5_governing.png|pdf
FIG = "fig5_governing"
CFG = section(FIG)
F5 = f"results/{FIG}"


rule fig5_governing_pack:
    priority: PRIORITY["fig5_governing"]
    input:
        code=code_of("fig5_governing_pack"),
    output:
        temp(f"{F5}/shards/packs_{{shard}}-of-{{n}}.nc"),
    wildcard_constraints:
        shard=r"\d+",
        n=r"\d+",
    params:
        config=without_shards(CFG),
    log:
        log(FIG, "pack_{shard}-of-{n}"),
    benchmark:
        bench(FIG, "pack_{shard}-of-{n}")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig5_governing_pack.py"


rule fig5_governing_analyse:
    priority: PRIORITY["fig5_governing"]
    input:
        packs=shard_files(FIG, "packs", CFG["shards"]),
        code=code_of("fig5_governing_analyse"),
    output:
        temp(f"{F5}/shards/analyses_{{shard}}-of-{{n}}.nc"),
    wildcard_constraints:
        shard=r"\d+",
        n=r"\d+",
    params:
        config=without_shards(CFG),
    log:
        log(FIG, "analyse_{shard}-of-{n}"),
    benchmark:
        bench(FIG, "analyse_{shard}-of-{n}")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig5_governing_analyse.py"


rule fig5_governing_merge:
    priority: PRIORITY["fig5_governing"]
    input:
        packs=shard_files(FIG, "packs", CFG["shards"]),
        analyses=shard_files(FIG, "analyses", CFG["shards"]),
        code=code_of("fig5_governing_merge"),
    output:
        f"{F5}/packings.nc",
    log:
        log(FIG, "merge"),
    benchmark:
        bench(FIG, "merge")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig5_governing_merge.py"


rule fig5_governing_notebook:
    input:
        packings=f"{F5}/packings.nc",
        flows=f"{F5}/flows.nc",
        notebook=notebook_file(FIG),
        notebook_py=notebook_file(FIG, "py"),
        code=notebook_code("fig5_governing"),
    output:
        # the report's caption is the finding, written by the notebook from the data
        png=report(f"results/figures/{FIG}.png", caption=os.path.abspath(f"{F5}/caption.rst"), category=FIG,
                   subcategory="PNG"),
        pdf=report(f"results/figures/{FIG}.pdf", caption=os.path.abspath(f"{F5}/caption.rst"), category=FIG,
                   subcategory="PDF"),
        caption=f"{F5}/caption.rst",
    params:
        config=without_shards(CFG),
    log:
        notebook=f"results/notebooks/{FIG}.ipynb",
    benchmark:
        bench(FIG, "notebook")
    conda:
        CONDA_ENV
    notebook:
        "../../notebooks/fig5_governing.ipynb"


rule fig5_governing:
    input:
        figure_targets(FIG),


# Flows: Figure 2's flow across mu, h and slope, one factor at a
# time around Figure 2's setting; scans of distinct solutions and why a line.
#   deposit   one deposit per seed (at the base mu), shared by every setting -> shards/deposit_seed<s>.nc
#   flow      the flows of one seed, one per setting, scanned (one job per seed,
#             so that its start-up is paid once)                          -> shards/flow_<i>_seed<s>.nc
#   flows     every flow                                                  -> flows.nc
from ncd.figures.fig5_governing import flow as _gflow

FLOWS = CFG["flows"]
FLOW_CFG = {"scene": section("fig2_slope")["scene"], "deposit": section("fig2_slope")["deposit"],
            "flows": without_shards(FLOWS)}
DEPOSIT_CFG = {"scene": FLOW_CFG["scene"], "deposit": FLOW_CFG["deposit"],
               "flows": {"base": {"mu": FLOWS["base"]["mu"]}, "root_seed": FLOWS["root_seed"]}}
FLOW_MU = _gflow.settings_table(FLOWS)["mu"]
FLOW_SHARDS = [f"{F5}/shards/flow_{i}_seed{s}.nc" for i in range(len(FLOW_MU)) for s in range(FLOWS["seeds"])]


rule fig5_governing_deposit:
    input:
        code=code_of("fig5_governing_deposit"),
    output:
        temp(f"{F5}/shards/deposit_seed{{s}}.nc"),
    wildcard_constraints:
        s=r"\d+",
    params:
        config=DEPOSIT_CFG,
    log:
        log(FIG, "deposit_seed{s}"),
    benchmark:
        bench(FIG, "deposit_seed{s}")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig5_governing_deposit.py"


rule fig5_governing_flow:
    input:
        deposit=f"{F5}/shards/deposit_seed{{s}}.nc",
        code=code_of("fig5_governing_flow"),
    output:
        [temp(f"{F5}/shards/flow_{i}_seed{{s}}.nc") for i in range(len(FLOW_MU))],
    wildcard_constraints:
        s=r"\d+",
    params:
        config=FLOW_CFG,
    log:
        log(FIG, "flow_seed{s}"),
    benchmark:
        bench(FIG, "flow_seed{s}")
    conda:
        CONDA_ENV
    script:
        "../scripts/fig5_governing_flow.py"


rule fig5_governing_flows:
    input:
        shards=FLOW_SHARDS,
        code=code_of("merge_shards"),
    output:
        f"{F5}/flows.nc",
    params:
        dim="flow",
    log:
        log(FIG, "flows"),
    benchmark:
        bench(FIG, "flows")
    conda:
        CONDA_ENV
    script:
        "../scripts/merge_shards.py"
