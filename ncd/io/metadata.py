"""Documented CF metadata of the variable names the figures write (``units``, ``long_name``).

A producer sets ``attrs={"units": ..., "long_name": ...}`` on what it creates;
:func:`ncd.io.netcdf.write_dataset` fills, from :data:`KNOWN`, what a producer left unset.
Units are SI as in ``config.yaml`` (lengths m, 2-D masses kg, forces N, impulses N s);
``"1"`` is dimensionless, an index or a count.  0/1 flags get CF ``flag_values`` and
``flag_meanings``.  A name absent here and without attributes is reported by
``write_dataset`` (an error under ``NCD_STRICT_METADATA=1``, as in the tests).
"""
import numpy as np

FLAG = ((0, 1), "false true")

# name: (units, long_name[, flags])
KNOWN = {
    # indices and labels
    "run": ("1", "member (run) index of the ensemble"),
    "disc": ("1", "disc index"), "grain": ("1", "grain index"), "contact": ("1", "contact index"),
    "prev_contact": ("1", "contact index at the previous step"), "wall": ("1", "wall index"),
    "ground": ("1", "index of a fixed ground disc"), "step": ("1", "time step index"),
    "deposit_step": ("1", "time step index of the deposition"), "scan_step": ("1", "scanned time step index"),
    "sample": ("1", "sample index"), "chain": ("1", "hit-and-run chain index"), "vertex": ("1", "vertex index"),
    "solution": ("1", "index of a distinct solution"), "cut": ("1", "cut index"), "bin": ("1", "bin index"),
    "frame": ("1", "stored frame index"), "key": ("1", "contact key (body pair code)"),
    "prev_key": ("1", "contact key at the previous step"), "body_a": ("1", "first body of the contact"),
    "body_b": ("1", "second body of the contact (walls after the discs)"),
    "case": ("1", "stability case"), "method": ("1", "integration method"), "kind": ("1", "kind"),
    "init": ("1", "initial guess of NLGS (zero, random or warm)"), "criterion": ("1", "NLGS stopping criterion"),
    "state": ("1", "state on which NLGS runs"), "evolution": ("1", "evolution (first-guess policy)"),
    "observable": ("1", "name of the observable"), "quantity": ("1", "measured quantity"),
    "tol": ("1", "NLGS tolerance (relative natural-map residual)"),
    # solver diagnostics
    "sweeps": ("1", "NLGS sweeps"), "residual": ("1", "relative natural-map residual of the Coulomb problem"),
    "change": ("1", "relative impulse change over the last sweep"), "converged": ("1", "NLGS converged", FLAG),
    "wall_time": ("s", "wall-clock time of the run (a measurement, differs between reruns)"),
    "reference_sweeps": ("1", "NLGS sweeps of the reference solution"),
    "reference_residual": ("1", "residual of the reference solution"),
    "reference_converged": ("1", "reference solution converged", FLAG),
    "max_velocity": ("1", "largest grain speed |u_f| (translation and r omega) / (|g| h)"),
    "max_speed": ("1", "largest grain speed / (|g| h)"),
    "observable_change": ("1", "largest relative change of the figure's observable over the last checks"),
    "finish_rounds": ("1", "LP solves of the exact finishing stage"),
    "finish_correction": ("1", "relative L1 move of the impulses by the finishing projection (0: none)"),
    "n_contacts": ("1", "number of contacts"), "n_discs": ("1", "number of discs"),
    "n_grains": ("1", "number of grains poured"), "n_steps": ("1", "number of time steps"),
    "unconverged_steps": ("1", "time steps whose NLGS did not converge"),
    "sweeps_mean": ("1", "mean NLGS sweeps per step (CD); -1 for MD"),
    "sweeps_max": ("1", "largest NLGS sweeps of a step (CD); -1 for MD"),
    "residual_max": ("1", "largest NLGS relative natural-map residual (CD); -1 for MD"),
    "deposit_sweeps": ("1", "NLGS sweeps per step of the deposition"),
    "first_reviewed": ("1", "contact solved first in each sweep"),
    "zero_guess": ("1", "run started from the zero guess", FLAG),
    "mode": ("1", "exploration mode of the run"),
    "status": ("1", "final status per contact: 0 no contact, 1 stick, 2/3 slide"),
    "outcome": ("1", "classified outcome of the run"),
    # geometry and state
    "x": ("m", "x of the disc centre"), "y": ("m", "y of the disc centre"),
    "pos_x": ("m", "x of the disc centre"), "pos_y": ("m", "y of the disc centre"),
    "vx": ("m s-1", "x velocity"), "vy": ("m s-1", "y velocity"),
    "vel_x": ("m s-1", "x velocity"), "vel_y": ("m s-1", "y velocity"),
    "spin": ("s-1", "angular velocity"), "radius": ("m", "disc radius"), "mass": ("kg", "disc mass"),
    "ground_x": ("m", "x of a ground disc centre"), "ground_y": ("m", "y of a ground disc centre"),
    "ground_radius": ("m", "radius of a ground disc"),
    "wall_point_x": ("m", "x of a point of the wall"), "wall_point_y": ("m", "y of a point of the wall"),
    "wall_normal_x": ("1", "x of the wall's unit normal"), "wall_normal_y": ("1", "y of the wall's unit normal"),
    "normal_x": ("1", "x of the contact's unit normal"), "normal_y": ("1", "y of the contact's unit normal"),
    "point_x": ("m", "x of the contact point"), "point_y": ("m", "y of the contact point"),
    "gap": ("m", "gap of the contact (negative: overlap)"), "contact_mu": ("1", "friction coefficient of the contact"),
    "mu": ("1", "friction coefficient"), "time": ("s", "time"),
    "kinetic_energy": ("J", "kinetic energy (per unit thickness)"),
    "deposit_kinetic_energy": ("J", "kinetic energy during the deposition"),
    "max_penetration": ("1", "largest interpenetration / diameter"),
    "deposit_max_penetration": ("1", "largest interpenetration / diameter during the deposition"),
    "mean_vx": ("m s-1", "mean x velocity of the discs"), "mean_vy": ("m s-1", "mean y velocity of the discs"),
    "source_height": ("m", "height of the pouring source"),
    # impulses, forces, accelerations
    "impulse_n": ("N s", "normal contact impulse"), "impulse_t": ("N s", "tangential contact impulse"),
    "prev_impulse_n": ("N s", "normal impulse at the previous step"),
    "prev_impulse_t": ("N s", "tangential impulse at the previous step"),
    "warm_guess_n": ("N s", "warm-start guess of the normal impulse"),
    "warm_guess_t": ("N s", "warm-start guess of the tangential impulse"),
    "warm_impulse_n": ("N s", "normal impulse of the last deposition step (the warm guess)"),
    "warm_impulse_t": ("N s", "tangential impulse of the last deposition step"),
    "force_n": ("N", "normal contact force"), "force_t": ("N", "tangential contact force"),
    "guess_force_n": ("N", "normal force of the initial guess"), "guess_force_t": ("N", "tangential force of the initial guess"),
    "rest_force_n": ("N", "normal force r = s/h of the equilibrium test"),
    "rest_force_t": ("N", "tangential force r = s/h of the equilibrium test"),
    "accel_x": ("m s-2", "x acceleration of the disc over the step"),
    "accel_y": ("m s-2", "y acceleration of the disc over the step"),
    "spin_accel": ("s-2", "angular acceleration of the disc over the step"),
    "reference_accel_x": ("m s-2", "x acceleration of the reference (warm) solution"),
    "reference_accel_y": ("m s-2", "y acceleration of the reference (warm) solution"),
    "solution_accel_x": ("m s-2", "x acceleration in a distinct solution"),
    "solution_accel_y": ("m s-2", "y acceleration in a distinct solution"),
    "mean_x": ("m s-2", "mean x acceleration over the runs"), "mean_y": ("m s-2", "mean y acceleration over the runs"),
    "cov_xx": ("m2 s-4", "covariance of the x acceleration"), "cov_xy": ("m2 s-4", "x-y covariance of the acceleration"),
    "cov_yy": ("m2 s-4", "covariance of the y acceleration"),
    "major": ("m s-2", "standard deviation along the major principal axis"),
    "minor": ("m s-2", "standard deviation along the minor principal axis"),
    "ratio": ("1", "minor / major principal standard deviation"),
    "spread": ("m s-2", "RMS distance of the acceleration to its mean over the runs, sqrt(major^2 + minor^2)"),
    "delta_x": ("m s-2", "x of the difference between two solutions"),
    "delta_y": ("m s-2", "y of the difference between two solutions"),
    "rigid_x": ("m s-2", "x of the rigid-motion part of the difference"),
    "rigid_y": ("m s-2", "y of the rigid-motion part of the difference"),
    "visible_fraction": ("1", "fraction of grains with a visible dispersion"),
    "cluster_size": ("1", "size of the grain's cluster of status switches"),
    "n_stick_both": ("1", "contacts sticking in both solutions"),
    "switch_distance": ("1", "contacts between the grain and the nearest status switch"),
    "switched": ("1", "contact status differs between the two solutions", FLAG),
    "reference_distance": ("m s-2", "distance of a solution to the reference"),
    "solution_count": ("1", "runs that reached the solution"), "solution_label": ("1", "solution reached by the run"),
    # fig1
    "I_x": ("m", "x of the point I"), "I_y": ("m", "height of I (NaN unless wedged)"),
    "gamma": ("degree", "friction angle atan(mu)"), "angle": ("degree", "angle"),
    "wedged_fraction": ("1", "fraction of the runs that wedge"), "n_converged": ("1", "converged runs"),
    # fig3
    "area": ("N2", "area of the projection polygon"), "outer_area": ("N2", "area of the outer polygon"),
    "bounded": ("1", "projection bounded", FLAG), "exact": ("1", "projection exact", FLAG),
    "displayed": ("1", "contact displayed in the figure", FLAG),
    "implicit_sliding": ("1", "|r_t| = mu r_n at every point of A ∩ C", FLAG),
    "implicit_zero": ("1", "r_n = 0 at every point of A ∩ C", FLAG),
    "n_lp": ("1", "linear programmes solved"), "n_vertices": ("1", "vertices of the projection"),
    "vertex_n": ("N", "normal force of a projection vertex"), "vertex_t": ("N", "tangential force of a projection vertex"),
    # fig4
    "cut_force_x": ("N", "x of the resultant across the cut"), "cut_force_y": ("N", "y of the resultant across the cut"),
    "history_fx": ("N", "x of the resultant of the history forces across the cut"),
    "history_fy": ("N", "y of the resultant of the history forces across the cut"),
    "history_angle": ("degree", "angle of the history resultant below the horizontal, pointing outward"),
    "history_deviation": ("degree", "history resultant angle minus free-surface slope"),
    "history_pressure": ("N m-1", "vertical ground force per unit length (history forces)"),
    "ground_pressure": ("N m-1", "vertical ground force per unit length"),
    "ground_fx": ("N", "x of the ground's total force"), "ground_fy": ("N", "y of the ground's total force"),
    "unbalanced_fy": ("N", "weight minus the ground's vertical force"),
    "n_moving": ("1", "grains not at rest"), "n_crossing": ("1", "contacts crossing the cut"),
    "n_loaded": ("1", "loaded contacts crossing the cut"), "outer": ("1", "side of the cut away from the apex"),
    "column_weight": ("N", "weight of the grains above the bin"),
    "bin_lo": ("m", "left edge of the bin"), "bin_hi": ("m", "right edge of the bin"),
    "cut_x": ("m", "x of the cut"), "depth": ("m", "depth of the cut below the surface"),
    "y_lo": ("m", "lower end of the cut"), "y_hi": ("m", "upper end of the cut"),
    "height": ("m", "height of the free surface"), "x_profile": ("m", "x of the surface profile"),
    "surface_angle": ("degree", "slope of the free surface"),
    # stability and work-precision
    "h": ("s", "time step"), "h_crit": ("s", "critical time step of MD"),
    "h_over_hcrit": ("1", "time step / MD critical step"), "k_n": ("N m-1", "normal stiffness of MD"),
    "k_factor": ("1", "stiffness / reference stiffness"), "restitution": ("1", "restitution coefficient"),
    "stable": ("1", "run stable", FLAG), "diverged": ("1", "run diverged", FLAG), "nan": ("1", "NaN reached", FLAG),
    "tunnelled": ("1", "a disc passed through an obstacle", FLAG),
    "diverged_step": ("1", "step of the divergence (-1: none)"),
    "energy_drift": ("1", "energy drift / E_s"), "energy_growth": ("1", "energy growth / E_s"),
    "observable_ref": ("1", "reference value of the observable"),
    "trace": ("1", "(E(t) - E_0) / E_s at evenly spaced steps"), "trace_points": ("1", "points of the trace"),
    "error": ("1", "error of the observable (relative for distance and mean velocity)"),
    "error_impulse": ("1", "|s - s*| / |s*|, s* the reference of the same init"),
    "error_velocity": ("1", "max |u_f - u_f*| / (|g| h)"),
    "limits_distance_impulse": ("1", "distance between the references of two inits (impulse)"),
    "limits_distance_velocity": ("1", "distance between the references of two inits (velocity)"),
    "reference": ("1", "reference value of the quantity"), "value": ("1", "value of the quantity"),
    "work": ("1", "CD: sum of sweeps x contacts; MD: steps x candidate pairs"),
    # the ensembles of piles (ncd.figures.fig4_history.analysis)
    "history": ("1", "construction history of the pile (point source or rain)"),
    "pile": ("1", "pile (ensemble member) index"), "flank": ("1", "flank of the pile (left or right)"),
    # the benchmark suite (ncd.studies.bench, results/bench/*.nc)
    "size": ("1", "discs of the benchmark packing"), "threads": ("1", "threads of the ensemble run"),
    "speedup": ("1", "wall time on one thread over wall time on this many threads"),
    "same_results": ("1", "outputs identical to the one-thread run, bit for bit", FLAG),
    "digest": ("1", "SHA-256 digest of every output of the ensemble"),
    "engine": ("1", "simulation engine"), "solver": ("1", "solver (plain NLGS or NLGS with the finishing stage)"),
    "job": ("1", "job index"), "figure": ("1", "figure"), "rule": ("1", "rule or job name"),
    "seconds": ("s", "wall time of the job"), "max_rss_mb": ("MB", "peak resident memory of the job"),
    "sweeps_zero": ("1", "NLGS sweeps to the tolerance from the zero guess"),
    "residual_zero": ("1", "relative natural-map residual reached from the zero guess"),
    "converged_zero": ("1", "reached the tolerance from the zero guess", FLAG),
    "wall_time_zero": ("s", "wall time of the solve from the zero guess"),
    "sweeps_interleaved": ("1", "NLGS sweeps to the tolerance from the zero guess, interleaved review order"),
    "residual_interleaved": ("1", "relative natural-map residual reached from the zero guess, interleaved review order"),
    "converged_interleaved": ("1", "reached the tolerance from the zero guess, interleaved review order", FLAG),
    "wall_time_interleaved": ("s", "wall time of the solve from the zero guess, interleaved review order"),
    "sweeps_warm": ("1", "NLGS sweeps to the tolerance from the warm guess"),
    "residual_warm": ("1", "relative natural-map residual reached from the warm guess"),
    "converged_warm": ("1", "reached the tolerance from the warm guess", FLAG),
    "wall_time_warm": ("s", "wall time of the solve from the warm guess"),
}

# name prefixes whose rest is a name of KNOWN (``scan_zero_sweeps``: sweeps of the scan, zero guess)
PREFIXES = {"scan_zero_": "scan, zero guess: ", "scan_warm_": "scan, warm start: ",
            "deposit_": "deposition: ", "snapshot_": "stored state: "}
SCAN = {"max_spread": ("m s-2", "largest RMS spread of a grain's acceleration over the converged runs (0: none converged)"),
        "solutions": ("1", "distinct solutions among the converged runs (0: none converged)"),
        "visible": ("1", "grains with a visible dispersion")}


def lookup(name):
    """(units, long_name[, flags]) of a known name, or None."""
    if name in KNOWN:
        return KNOWN[name]
    for prefix, label in PREFIXES.items():
        if name.startswith(prefix):
            rest = name[len(prefix):]
            entry = KNOWN.get(rest) or SCAN.get(rest)
            if entry:
                return (entry[0], label + entry[1], *entry[2:])
    return None


def default_attrs(name, var):
    """The attributes ``write_dataset`` adds to ``var`` when missing: a ``description`` becomes
    the ``long_name``; string variables get no units; 0/1 flags get flag_values/meanings."""
    out = {}
    entry = lookup(name)
    if entry is not None:
        out["units"], out["long_name"] = entry[0], entry[1]
        if len(entry) > 2 and var.dtype.kind in "iub" and "flag_values" not in var.attrs:
            values, meanings = entry[2]
            out["flag_values"] = np.array(values, dtype=var.dtype if var.dtype.kind != "b" else np.int8)
            out["flag_meanings"] = meanings
    if str(var.attrs.get("description", "")).strip():
        out["long_name"] = var.attrs["description"]
    if var.dtype.kind in "OSU":
        out.pop("units", None)
    return out
