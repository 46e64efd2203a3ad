"""Time to tolerance (1e-6, 1e-8, 1e-10): plain NLGS and NLGS + finishing stage side by side,
on the dense packings (-> tolerance.nc) and on the pile's final state and Figure 2's
investigated step, from the zero guess, and that step from the previous step's impulses, identity and random
review orders (-> tolerance_problems.nc)."""
import numpy as np
import xarray as xr

from ncd.dynamics.stepper import initial_guess, prepare_step
from ncd.io.netcdf import provenance, write_dataset
from ncd.pipeline.jobs import start
from ncd.shared import pile, slope
from ncd.studies.bench.finish import FIELDS, METHODS, time_to_tolerance
from ncd.studies.bench.solver import environment, tolerance_table

log = start(snakemake)  # snakemake is injected
cfg = snakemake.params.config
ds = tolerance_table(cfg, log)
ds.attrs.update(provenance(cfg, **environment()))
write_dataset(ds, snakemake.output.packings)

pcfg, scfg = snakemake.params.pile, snakemake.params.slope
construction = xr.load_dataset(snakemake.input.construction)
scene = pile.final_scene(pcfg, construction)
problems = {"pile": (scene, pile.equilibrium_problem(pcfg, scene, construction), None)}
traj = xr.load_dataset(snakemake.input.trajectory)
scene = slope.scene_at_step(traj, scfg)
step = prepare_step(scene, float(traj.attrs["h"]))
problems["fig2_step"] = (scene, step, None)
problems["fig2_step_warm"] = (scene, step, initial_guess(scene, step, "warm"))
out = {k: [] for k in FIELDS}
for name, (scene, problem, guess) in problems.items():
    n = problem.contacts.n
    orders = [None] + [np.random.default_rng((k, cfg["root_seed"])).permutation(n) for k in range(1, cfg["orders"])]
    res = time_to_tolerance(scene, problem, cfg["tolerances"], cfg["handoff"], cfg["problem_sweeps"], orders,
                            log=log, label=name, guess=guess)
    for k in FIELDS:
        out[k].append(res[k])
ds = xr.Dataset({k: (("problem", "order", "solver", "tol"), np.array(v), {"units": FIELDS[k][0], "long_name": FIELDS[k][1]})
                 for k, v in out.items()},
                coords={"problem": list(problems), "order": np.arange(cfg["orders"]), "solver": list(METHODS),
                        "tol": cfg["tolerances"]})
ds["problem"].attrs.update(units="1", long_name="step problem: the pile's final state, fig2's investigated step "
                                                "from the zero guess and from the previous step's impulses (warm)")
ds["order"].attrs.update(units="1", long_name="review order: 0 identity, k > 0 permutation of rng((k, root_seed))")
ds.attrs.update(provenance(cfg, **environment()))
write_dataset(ds, snakemake.output.problems)
