"""Random malformed calls of the public API, for :mod:`test_fuzz`.

``call(entry, rng)`` draws one call of ``entry`` from a valid baseline (small
random scenes: overlapping discs, mass ratios up to 1e12, periodic or walled,
obstacle discs; random SPD, indefinite or non-symmetric ``W``; empty problems)
and spoils zero to three of its arguments: wrong shapes and dtypes, NaN/inf,
huge and tiny values, out-of-range indices and non-permutations, corrupted
scene or problem fields.  Sweep budgets stay below 300.
"""
import numpy as np

# ------------------------------------------------------------------ generators
BAD_SCALARS = [np.nan, np.inf, -np.inf, -1.0, 0.0, -0.0, 1e308, -1e308, 1e-308, 1e300, -1e-300, 1.5, 2,
               True, None, "0.5", [0.5], np.array([1.0, 2.0]), 1 + 1j, np.float32(0.3), np.int64(3), 10**30]


def bad_scalar(rng):
    return BAD_SCALARS[rng.integers(len(BAD_SCALARS))]


def spoil_array(rng, arr):
    """A malformed variant of ``arr`` (shape, dtype, values or type)."""
    try:
        arr = np.array(arr, dtype=float)
    except (TypeError, ValueError):       # already spoiled: keep it
        return arr
    k = rng.integers(16)
    if k == 0:
        return arr.T.copy() if arr.ndim == 2 else arr[:-1]
    if k == 1:
        return arr[:-1] if len(arr) else np.zeros(3)
    if k == 2:
        return np.concatenate([arr, arr[:1]]) if len(arr) else np.ones((1,) + arr.shape[1:])
    if k == 3:
        return arr.ravel()
    if k == 4:
        return arr[None]
    if k == 5:
        return np.zeros((0,) + arr.shape[1:])
    if k in (6, 7, 8) and arr.size:
        out = arr.copy()
        out.flat[rng.integers(arr.size)] = [np.nan, np.inf, -np.inf][k - 6]
        return out
    if k == 9:
        return arr * 1e300
    if k == 10:
        return arr * 1e-300
    if k == 11:
        return arr.astype(str)
    if k == 12:
        return arr.astype(bool)
    if k == 13:
        return arr.tolist() + [[1.0]] if arr.ndim == 2 else arr.tolist() + [[1.0, 2.0]]
    if k == 14:
        return None if rng.random() < 0.5 else "array"
    return np.column_stack([arr, arr]) if arr.ndim == 2 else arr.reshape(-1, 1)


def spoil_order(rng, n):
    k = rng.integers(9)
    base = rng.permutation(n)
    if k == 0:
        return [0, 1, 10**6][: max(n, 1)] if n <= 3 else np.concatenate([base[:-1], [10**6]])
    if k == 1:
        return np.zeros(n, int) if n else [0]
    if k == 2:
        return base.astype(float)
    if k == 3:
        return np.concatenate([base, [0]])
    if k == 4:
        return base[:-1]
    if k == 5:
        return -1 - base
    if k == 6:
        return base.astype(np.uint64) + np.uint64(2**63)
    if k == 7:
        return [str(i) for i in base]
    return base.reshape(1, -1)


def settings_kwargs(rng):
    return dict(tol=float(10.0 ** rng.uniform(-12, -4)), max_sweeps=int(rng.integers(1, 300)),
                check_every=int(rng.integers(1, 5)), criterion=["residual", "change"][rng.integers(2)])


def settings(rng):
    import ncd
    return ncd.SolverSettings(**settings_kwargs(rng))


def scene_kwargs(rng):
    """A random valid-looking scene: overlaps allowed, mass ratios up to 1e12."""
    n = int(rng.integers(1, 7))
    r = rng.uniform(0.2, 0.6, n)
    x = np.cumsum(2 * r) - r + rng.uniform(-0.3, 0.3, n)          # may overlap
    y = r * rng.uniform(0.9, 1.6, n)
    kw = dict(pos=np.column_stack([x, y]), radius=r if rng.random() < 0.5 else 0.4,
              density=10.0 ** rng.uniform(0, 12, n) if rng.random() < 0.5 else 1.0,
              walls=[((0.0, 0.0), (0.0, 1.0))], mu=float(rng.choice([0.0, 0.3, 1.0, 10.0])),
              e_n=float(rng.choice([0.0, 0.5, 1.0])), overlap_tolerance=3.0,
              vel=rng.normal(size=(n, 2)) if rng.random() < 0.3 else None)
    if rng.random() < 0.3:
        kw["obstacle_pos"] = np.column_stack([x[:1] + 1.0, [-0.2]])
        kw["obstacle_radius"] = 0.4
    if rng.random() < 0.2:
        kw["period"] = float(2 * r.sum() + 10.0)
    return kw


def make_scene(rng):
    import ncd
    return ncd.make_scene(**scene_kwargs(rng))


def spoil_scene(rng, s):
    """Corrupt one field of a built scene, as a user editing it by hand might."""
    field = ["pos", "vel", "spin", "angle", "radius", "inv_mass", "inv_inertia", "mass", "wall_point",
             "wall_normal", "gravity", "n_mobile", "mu", "e_n", "period", "prev_keys"][rng.integers(16)]
    if field == "n_mobile":
        s.n_mobile = [0, s.n_disc + 1, 1.5, -1][rng.integers(4)]
    elif field in ("mu", "e_n", "period"):
        setattr(s, field, bad_scalar(rng))
    elif field == "prev_keys":
        s.prev_keys, s.prev_impulse = np.arange(3), np.zeros((int(rng.integers(0, 6)), 2))
    else:
        setattr(s, field, spoil_array(rng, getattr(s, field)))
    return s


def local_problem(rng):
    n = int(rng.integers(0, 6))
    A = rng.normal(size=(2 * n, 2 * n))
    kind = rng.integers(4)
    W = A @ A.T + 0.1 * np.eye(2 * n)
    if kind == 1:
        W = A + A.T                       # indefinite
    elif kind == 2:
        W = W + 0.3 * (A - A.T)           # non-symmetric
    q = rng.normal(size=2 * n)
    return W, q, float(rng.choice([0.0, 0.5, 2.0]))


# ------------------------------------------------------------------ one call per entry point
def call(entry, rng):
    """Draw and run one call of ``entry``; returns its result."""
    import scipy.sparse as sp

    import ncd
    from ncd.dynamics.explore import explore
    bad = rng.random(3) < 0.4             # which argument groups to spoil
    if entry == "make_scene":
        kw = scene_kwargs(rng)
        for _ in range(int(rng.integers(0, 3))):
            key = list(kw)[rng.integers(len(kw))] if rng.random() < 0.9 else "pos"
            v = kw[key]
            kw[key] = spoil_array(rng, v) if isinstance(v, np.ndarray) else bad_scalar(rng)
        if rng.random() < 0.05:
            kw["pos"] = np.zeros((0, 2))
        return ncd.make_scene(**kw)
    if entry == "SolverSettings":
        kw = settings_kwargs(rng)
        key = list(kw)[rng.integers(len(kw))]
        kw[key] = bad_scalar(rng) if rng.random() < 0.8 else "energy"
        return ncd.SolverSettings(**kw)
    if entry in ("project_cone", "solve_single_contact_py"):
        args = [rng.normal(), rng.normal(), abs(rng.normal())]
        if entry == "solve_single_contact_py":
            W, q, mu = local_problem(rng)
            args = [W[:2, :2] if len(W) else np.eye(2), q[:2] if len(q) else [-1.0, 0.0], mu]
            if bad[0]:
                args[0] = spoil_array(rng, args[0])
            if bad[1]:
                args[1] = spoil_array(rng, args[1])
            if bad[2]:
                args[2] = bad_scalar(rng)
            return getattr(ncd, entry)(*args)
        for i in range(3):
            if bad[i]:
                args[i] = bad_scalar(rng)
        return ncd.project_cone(*args)
    if entry == "solve_local":
        W, q, mu = local_problem(rng)
        n = len(q) // 2
        kw = dict(guess=None, review_order=None, settings=settings(rng))
        if bad[0]:
            W = spoil_array(rng, W) if rng.random() < 0.7 else W * np.nan
        if bad[1]:
            q = spoil_array(rng, q)
        if bad[2]:
            which = rng.integers(4)
            if which == 0:
                mu = bad_scalar(rng)
            elif which == 1:
                kw["guess"] = spoil_array(rng, np.zeros((n, 2)))
            elif which == 2:
                kw["review_order"] = spoil_order(rng, n)
            else:
                kw["settings"] = {"max_sweeps": 10}
        if rng.random() < 0.3 and isinstance(W, np.ndarray) and W.ndim == 2 and W.dtype.kind == "f":
            W = sp.csr_matrix(W)
        return ncd.solve_local(W, q, mu, **kw)

    s = make_scene(rng)
    if rng.random() < 0.15:
        ncd.step(s, 1e-3)                    # warm-start memory
    h = 1e-3
    if entry in ("detect_contacts", "kinetic_energy"):
        if bad[0]:
            spoil_scene(rng, s)
        if entry == "kinetic_energy":
            return ncd.kinetic_energy(s)
        alert = bad_scalar(rng) if bad[1] else 1e-9
        pos = spoil_array(rng, s.pos) if bad[2] else None
        return ncd.detect_contacts(s, alert=alert, pos=pos)
    if entry in ("prepare_step", "step", "equilibrium_test"):
        kw = {}
        if bad[0]:
            spoil_scene(rng, s)
        if bad[1]:
            key = ["h", "theta", "gap_tolerance", "speed_limit", "velocity_tol"][rng.integers(5)]
            if key == "h":
                h = bad_scalar(rng)
            elif entry == "step" or key in ("gap_tolerance", "theta", "velocity_tol"):
                if not (entry == "equilibrium_test" and key in ("theta", "speed_limit")) \
                        and not (entry == "step" and key == "velocity_tol") \
                        and not (entry == "prepare_step" and key == "velocity_tol"):
                    kw[key] = bad_scalar(rng)
        if bad[2]:
            if entry == "prepare_step":
                kw["vel" if rng.random() < 0.5 else "spin"] = spoil_array(rng, s.vel if rng.random() < 0.5 else s.spin)
            else:
                which = rng.integers(3)
                if which == 0:
                    kw["init"] = [spoil_array(rng, np.zeros((3, 2))), "hot", None, 3][rng.integers(4)]
                elif which == 1:
                    kw["review_order"] = spoil_order(rng, int(rng.integers(0, 8)))
                else:
                    kw["settings"] = "fast"
        if entry != "prepare_step":
            kw.setdefault("settings", settings(rng))
        return getattr(ncd, entry)(s, h, **kw)

    p = ncd.prepare_step(s, h)
    n = p.contacts.n
    if bad[0]:
        k = rng.integers(5)
        if k == 0:
            spoil_scene(rng, s)
        elif k == 1:
            p = ncd.prepare_step(make_scene(rng), h)          # a problem of another scene
        elif k == 2:
            field = ["W", "free_vel", "free_spin", "bias"][rng.integers(4)]
            setattr(p, field, spoil_array(rng, getattr(p, field)))
        elif k == 3 and n:
            field = ["body_a", "body_b", "normal", "arm_a", "mu", "e_n"][rng.integers(6)]
            arr = getattr(p.contacts, field).copy()
            if arr.dtype.kind == "i":
                arr[rng.integers(n)] = [10**6, -10**6, -1, s.n_disc][rng.integers(4)]
            else:
                arr.flat[rng.integers(arr.size)] = [np.nan, np.inf, -np.inf, -1.0, 1e308, 1e-308][rng.integers(6)]
            setattr(p.contacts, field, arr)
        else:
            p = "problem"
    kw = dict(settings=settings(rng))
    if bad[1]:
        kw["settings" if rng.random() < 0.2 else "review_order"] = spoil_order(rng, n)
    if entry == "explore":
        members = np.arange(int(rng.integers(0, 3)))
        kw.update(init=["zero", "warm", "random"][rng.integers(3)], review=["fixed", "random"][rng.integers(2)],
                  guess_scale=0.01, threads=int(rng.integers(1, 3)))
        kw.pop("review_order", None)
        root = 7
        if bad[2]:
            key = ["members", "root_seed", "guess_scale", "threads", "init", "review"][rng.integers(6)]
            if key == "members":
                members = spoil_order(rng, 3)
            elif key == "root_seed":
                root = bad_scalar(rng)
            else:
                kw[key] = bad_scalar(rng)
        return explore(s, p, members, root, **kw)
    if bad[2]:
        kw["guess"] = spoil_array(rng, np.zeros((n, 2)))
    if entry == "solve_problem":
        return ncd.solve_problem(s, p, **kw)
    if isinstance(p, str):
        return ncd.solve_discs(s, p, np.zeros((s.n_disc, 2)), np.zeros(s.n_disc), **kw)
    vel, spin = (v.copy() if isinstance(v, np.ndarray) else v for v in (p.free_vel, p.free_spin))
    if bad[0] and rng.random() < 0.5:
        vel = spoil_array(rng, vel)
    result = ncd.solve_discs(s, p.contacts, vel, spin, bias=p.bias, W=p.W, **kw)
    return result, vel, spin
