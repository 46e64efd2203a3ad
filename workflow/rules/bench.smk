# Benchmark suite: `snakemake -j2 bench`, not part of the default target.
#   core      ns per contact update (numba and the same loop in C), detection,
#             time per step and memory on dense packings       -> results/bench/core.nc
#   sweeps    sweeps to a fixed tolerance against N             -> results/bench/sweeps.nc
#   tolerance time to 1e-6/1e-8/1e-10, NLGS, NLGS + finish, Anderson, and local exact
#             solves -> results/bench/tolerance.nc (dense packings), tolerance_problems.nc
#             (the pile's final state, fig2's step from the zero and the warm guess)
#   ensemble  NLGS ensemble on 1 and 2 threads                  -> results/bench/ensemble.nc
#   peer      ncd and pymunk side by side on a poured pile      -> results/bench/peer.nc
#   rules     wall time of every rule of the figures' run       -> results/bench/rules.nc
#   dag       CPU seconds of every job of the default run and the
#             critical path of its DAG                          -> results/bench/dag.nc
#   sampler   Figure 5's hit-and-run, random and coordinate directions on the same slices
#                                                              -> results/bench/sampler.nc
#   profile   the figures run again with config/quick.yaml's counts in a scratch directory
#             under py-spy: each figure's share of CPU in numba kernels, LP solvers,
#             other compiled code and Python                    -> results/bench/profile.nc
#   notebook  notebooks/bench.ipynb                             -> results/figures/bench.png|pdf
# Every timing rule asks for all the cores (threads: BENCH_THREADS), so that with -j2
# Snakemake runs it alone: no other job competes with what it measures.
FIGB = "bench"
CFGB = section(FIGB)
BENCH_THREADS = 2


rule bench_core:
    input:
        code=code_of("bench_core"),
    output:
        "results/bench/core.nc",
    threads: BENCH_THREADS
    params:
        config=CFGB["core"],
    log:
        log(FIGB, "core"),
    benchmark:
        bench(FIGB, "core")
    conda:
        CONDA_ENV
    script:
        "../scripts/bench_core.py"


rule bench_sweeps:
    input:
        code=code_of("bench_sweeps"),
    output:
        "results/bench/sweeps.nc",
    threads: BENCH_THREADS
    params:
        config=CFGB["sweeps"],
    log:
        log(FIGB, "sweeps"),
    benchmark:
        bench(FIGB, "sweeps")
    conda:
        CONDA_ENV
    script:
        "../scripts/bench_sweeps.py"


rule bench_tolerance:
    input:
        construction="results/fig4_pile/construction.nc",
        trajectory="results/fig2_slope/trajectory.nc",
        code=code_of("bench_tolerance"),
    output:
        packings="results/bench/tolerance.nc",
        problems="results/bench/tolerance_problems.nc",
    threads: BENCH_THREADS
    params:
        config=CFGB["tolerance"],
        pile=without_shards(section("fig4_pile")),
        slope=without_shards(section("fig2_slope")),
    log:
        log(FIGB, "tolerance"),
    benchmark:
        bench(FIGB, "tolerance")
    conda:
        CONDA_ENV
    script:
        "../scripts/bench_tolerance.py"


rule bench_ensemble:
    input:
        code=code_of("bench_ensemble"),
    output:
        "results/bench/ensemble.nc",
    threads: BENCH_THREADS
    params:
        config=CFGB["ensemble"],
    log:
        log(FIGB, "ensemble"),
    benchmark:
        bench(FIGB, "ensemble")
    conda:
        CONDA_ENV
    script:
        "../scripts/bench_ensemble.py"


rule bench_peer:
    input:
        code=code_of("bench_peer"),
    output:
        "results/bench/peer.nc",
    threads: BENCH_THREADS
    params:
        config=CFGB["peer"],
    log:
        log(FIGB, "peer"),
    benchmark:
        bench(FIGB, "peer")
    conda:
        CONDA_ENV
    script:
        "../scripts/bench_peer.py"


rule bench_rules:
    """The wall time of every rule of the figures (their benchmark files, after their run)."""
    input:
        [figure_targets(f) for f in FIGURES],
        code=code_of("bench_rules"),
    output:
        "results/bench/rules.nc",
    params:
        pattern="results/benchmarks/*/*.tsv",
        figures=FIGURES,
    log:
        log(FIGB, "rules"),
    benchmark:
        bench(FIGB, "rules")
    conda:
        CONDA_ENV
    script:
        "../scripts/bench_rules.py"


rule bench_exact:
    """The LP time of the exact angle ranges of every pile of fig4_history (its exact files,
    and those of the size study when it has run)."""
    input:
        figure_targets("fig4_history"),
        code=code_of("bench_exact"),
    output:
        "results/bench/exact_sets.nc",
    params:
        pattern="results/fig4_history/exact/n*/*.nc",
    log:
        log(FIGB, "exact"),
    benchmark:
        bench(FIGB, "exact")
    conda:
        CONDA_ENV
    script:
        "../scripts/bench_exact.py"


rule bench_sampler:
    """Figure 5's uniform sampler with random and with coordinate directions in the rounded
    frame, on the same slices of this run's packings (ncd.figures.fig5_governing.sampler)."""
    input:
        packings="results/fig5_governing/packings.nc",
        code=code_of("bench_sampler"),
    output:
        "results/bench/sampler.nc",
    threads: BENCH_THREADS
    params:
        config=without_shards(section("fig5_governing")),
        per_mu=CFGB["sampler"]["per_mu"],
        root_seed=CFGB["sampler"]["root_seed"],
    log:
        log(FIGB, "sampler"),
    benchmark:
        bench(FIGB, "sampler")
    conda:
        CONDA_ENV
    script:
        "../scripts/bench_sampler.py"


rule bench_dag:
    """CPU seconds of every job of the default run and the critical path of its DAG
    (the job graph from a dry run, the times from the benchmark files)."""
    input:
        [figure_targets(f) for f in FIGURES],
        "results/index.html",
        code=code_of("bench_dag"),
    output:
        "results/bench/dag.nc",
    params:
        targets=["all"],
        cores=2,
    log:
        log(FIGB, "dag"),
    benchmark:
        bench(FIGB, "dag")
    conda:
        CONDA_ENV
    script:
        "../scripts/bench_dag.py"


rule bench_profile:
    """Where the figures' CPU goes: the figures' jobs run again (config/quick.yaml's counts,
    as caps over this run's config) in a scratch working directory under
    ``py-spy record --subprocesses --native``, every sample filed under its job's figure
    (read from the rules files) and its category (ncd.studies.bench.profile).  The run is
    of the real jobs, with the numba cache of this checkout, as a run here would be."""
    input:
        overlay="config/quick.yaml",     # the counts of the profiled run (caps over this run's config)
        code=code_of("bench_profile"),
    output:
        "results/bench/profile.nc",
    threads: BENCH_THREADS
    params:
        root=str(REL),
        overlay="config/quick.yaml",
        targets=CFGB.get("profile", {}).get("figures", FIGURES),
        figures=FIGURES,
        cores=BENCH_THREADS,
        rate=CFGB.get("profile", {}).get("rate", 25),
    log:
        log(FIGB, "profile"),
        run=log(FIGB, "profile_run"),
    benchmark:
        bench(FIGB, "profile")
    conda:
        CONDA_ENV
    script:
        "../scripts/bench_profile.py"


rule bench_notebook:
    input:
        core="results/bench/core.nc",
        sweeps="results/bench/sweeps.nc",
        tolerance="results/bench/tolerance.nc",
        tolerance_problems="results/bench/tolerance_problems.nc",
        ensemble="results/bench/ensemble.nc",
        peer="results/bench/peer.nc",
        rules="results/bench/rules.nc",
        dag="results/bench/dag.nc",
        profile="results/bench/profile.nc",
        exact_sets="results/bench/exact_sets.nc",
        sampler="results/bench/sampler.nc",
        notebook=notebook_file("bench"),
        notebook_py=notebook_file("bench", "py"),
        code=notebook_code("bench"),
    output:
        png=figure_output("bench", "png"),
        pdf=figure_output("bench", "pdf"),
    log:
        notebook="results/notebooks/bench.ipynb",
    benchmark:
        bench(FIGB, "notebook")
    conda:
        CONDA_ENV
    notebook:
        "../../notebooks/bench.ipynb"


rule bench:
    input:
        figure_targets(FIGB),
