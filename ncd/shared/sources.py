"""Grain sources of a pile construction (Moreau 2005, section 5): two histories of the same grains.

* :class:`PointSource` -- a localized source above ``x = 0`` rising with the pile
  (Figure 4; such piles show a pressure dip under the apex in Vanel et al. 1999 and
  Geng et al. 2001);
* :class:`SieveRain` -- a rain through a sieve that follows the growing heap: it spans the
  central part of the current heap's footprint, so that grains land on the heap and the
  heap grows at its angle of repose, as the point source's does (the "rain" of those
  experiments, which build heaps of the same shape by both procedures);
* :class:`RainSource` -- a uniform rain over a fixed ``|x| <= half_width`` from the first
  grain on: it deposits a layer, not a heap.

Both expose ``update_height``, ``draw`` and the state a checkpoint needs.  Given
``radii``, grains come in that order (the same grains for both histories); otherwise
each radius is drawn when its site is tried, which keeps Figure 4's pile bit for bit.
"""
import numpy as np


def mean_diameter(cfg):
    """Mean diameter of the grains (radii uniform in ``[radius_min, radius_max]``)."""
    return cfg["grains"]["radius_min"] + cfg["grains"]["radius_max"]


class _Source:
    """Common part: grain sizes, drop height above the settled grains, inlet speed."""

    def __init__(self, cfg, rng, y_ground, half_span, radii=None):
        s = cfg["source"]
        g = cfg["grains"]
        self.cfg, self.rng, self.d = s, rng, mean_diameter(cfg)
        self.rmin, self.rmax = g["radius_min"], g["radius_max"]
        self.radii = None if radii is None else np.asarray(radii, float)
        self.taken = 0                      # grains already inserted from ``radii``
        self.half_span = half_span          # settled grains within this |x| (plus d) set the height
        self.speed = s["inlet_speed"] * np.sqrt(cfg["gravity"] * self.d)
        self.y_ground = y_ground
        self.height = y_ground + (s["drop_height_d"] + 0.5) * self.d
        self.settle_speed = 0.2 * np.sqrt(cfg["gravity"] * self.d)

    def update_height(self, pos, radius, vel, age_ok):
        """Raise the source above the settled grains within one diameter of its span
        (the height never decreases)."""
        near = (np.abs(pos[:, 0]) < self.half_span + self.d) & age_ok
        near &= np.hypot(vel[:, 0], vel[:, 1]) < self.settle_speed
        if near.any():
            top = float(np.max(pos[near, 1] + radius[near]))
            self.height = max(self.height, top + (self.cfg["drop_height_d"] + 0.5) * self.d)

    def _near(self, pos, radius):
        """The grains that can touch a grain inserted at or above ``height``: an excluded
        grain lies more than two largest radii, the clearance and one diameter below it, so
        :meth:`_try` decides as it would against every grain (the same insertions, bit for
        bit), with O(n) work per attempt instead of per site."""
        if len(radius) == 0:
            return pos, radius
        reach = max(float(radius.max()), self.rmax) * 2.0 + 0.05 * self.d + self.d
        keep = pos[:, 1] > self.height - reach
        return pos[keep], radius[keep]

    def _radius(self):
        return self.rng.uniform(self.rmin, self.rmax) if self.radii is None else self.radii[self.taken]

    def _try(self, x, r, pos, radius, new_p, new_r, dy=0.0):
        """Insert a grain of radius ``r`` at ``(x, height + dy)`` if it clears every grain by 0.05 d."""
        clear = 0.05 * self.d
        y = self.height + dy
        # column by column and scalar by scalar: the distances of np.hypot(*(pos - p).T),
        # bit for bit, without a temporary (n, 2) array on each of the many attempts
        ok = len(radius) == 0 or np.min(np.hypot(pos[:, 0] - x, pos[:, 1] - y) - radius - r) > clear
        ok = ok and all(np.hypot(q[0] - x, q[1] - y) > r + rq + clear for q, rq in zip(new_p, new_r))
        if ok:
            new_p.append(np.array([x, y]))
            new_r.append(r)
            if self.radii is not None:
                self.taken += 1
        return ok

    def velocities(self, count):
        """Initial velocities of ``count`` new grains: straight down at the inlet speed."""
        return np.tile([0.0, -self.speed], (count, 1))

    def state(self):
        """What a checkpoint stores (besides the generator)."""
        return {"height": self.height, "taken": self.taken}

    def restore(self, state, rng_state):
        self.height, self.taken = float(state["height"]), int(state["taken"])
        self.rng.bit_generator.state = rng_state


class PointSource(_Source):
    """A localized source above the pile axis ``x = 0``: ``slots`` insertion sites in a
    row, ``drop_height_d`` mean diameters above the settled grains under it (so that
    impacts stay gentle while the pile grows); ``source.rows`` (default 1) grains are
    tried per site, stacked ``2.2 radius_max`` apart (same speed; a site refills when its
    column has fallen, so the steady flux per site stays ``inlet_speed / pitch``)."""

    def __init__(self, cfg, rng, y_ground, radii=None):
        s = cfg["source"]
        g = cfg["grains"]
        pitch = 2.2 * g["radius_max"]
        super().__init__(cfg, rng, y_ground, 0.5 * s["slots"] * pitch, radii)
        self.slots = (np.arange(s["slots"]) - (s["slots"] - 1) / 2) * pitch
        self.half_width = self.half_span
        self.rows, self.pitch = int(s.get("rows", 1)), pitch

    def draw(self, pos, radius, limit):
        """New grains at free sites (clearance ``0.05 d``): positions and radii."""
        new_p, new_r = [], []
        pos, radius = self._near(pos, radius)
        for x in self.slots[self.rng.permutation(len(self.slots))]:
            for j in range(self.rows):
                if len(new_r) >= limit:
                    break
                r = self._radius()
                self._try(x + self.rng.uniform(-1, 1) * self.cfg["jitter_d"] * self.d, r, pos, radius, new_p, new_r,
                          j * self.pitch)
        return np.array(new_p).reshape(-1, 2), np.array(new_r)


class RainSource(_Source):
    """Rain over ``|x| <= half_width``: ``sites`` positions drawn uniformly per attempt,
    at ``drop_height_d`` above the highest settled grain under the rain."""

    def __init__(self, cfg, rng, y_ground, half_width, sites, radii=None, spread=0.0):
        if not (np.isfinite(half_width) and half_width > 0):
            raise ValueError(f"rain half_width = {half_width!r} must be > 0")
        super().__init__(cfg, rng, y_ground, float(half_width), radii)
        self.half_width, self.sites = float(half_width), int(sites)
        self.spread = float(spread) * np.sqrt(cfg["gravity"] * self.d)

    def velocities(self, count):
        """Straight down at the inlet speed, plus a horizontal speed uniform in
        ``± spread sqrt(g d)`` (drawn after the positions; none when 0)."""
        v = super().velocities(count)
        if self.spread > 0:
            v[:, 0] = self.rng.uniform(-self.spread, self.spread, count)
        return v

    def draw(self, pos, radius, limit):
        new_p, new_r = [], []
        pos, radius = self._near(pos, radius)
        for x in self.rng.uniform(-self.half_width, self.half_width, self.sites):
            if len(new_r) >= limit:
                break
            self._try(x, self._radius(), pos, radius, new_p, new_r)
        return np.array(new_p).reshape(-1, 2), np.array(new_r)


class SieveRain(_Source):
    """A rain through a sieve that widens with the heap: ``sites`` positions per attempt,
    uniform over ``|x| <= fraction * W``, ``W`` the current footprint half-width (the
    ``trim``-th largest ``|x| + r`` of the settled grains, so that a grain rolled away does
    not widen the sieve), never narrower than the point source's row of sites.

    Why it builds the point source's heap: a uniform deposit over the central part of a
    heap standing at its angle of repose raises that part evenly and steepens the flank
    at the sieve's edge, which avalanches back to the angle of repose, so the heap stays
    a cone at repose; a sieve wider than the heap (:class:`RainSource` at first) deposits
    a layer instead."""

    def __init__(self, cfg, rng, y_ground, radii=None):
        r = cfg["rain"]
        g = cfg["grains"]
        self.min_half = 0.5 * cfg["source"]["slots"] * 2.2 * g["radius_max"]
        super().__init__(cfg, rng, y_ground, self.min_half, radii)
        self.fraction, self.sites, self.trim = float(r["footprint_fraction"]), int(r["sites"]), int(r["trim"])
        self.drop_d = float(r["drop_height_d"])
        if not 0.0 < self.fraction <= 1.0:
            raise ValueError(f"rain.footprint_fraction = {self.fraction!r} must lie in (0, 1]")
        self.half_width = self.min_half
        self.settled = np.zeros(0, bool)      # the settled grains at the last update_height (draw's surface)

    def update_height(self, pos, radius, vel, age_ok):
        """Widen the sieve to ``fraction`` of the settled heap's footprint (it never
        narrows), then raise it above the settled grains under it."""
        settled = age_ok & (np.hypot(vel[:, 0], vel[:, 1]) < self.settle_speed)
        self.settled = settled
        if settled.sum() > self.trim:
            reach = np.sort(np.abs(pos[settled, 0]) + radius[settled])[-1 - self.trim]
            self.half_width = max(self.half_width, self.min_half, self.fraction * float(reach))
            self.half_span = self.half_width
        super().update_height(pos, radius, vel, age_ok)

    def state(self):
        return {**super().state(), "half_width": self.half_width}

    def restore(self, state, rng_state):
        super().restore(state, rng_state)
        self.half_width = self.half_span = float(state.get("half_width", self.min_half))

    def draw(self, pos, radius, limit):
        """New grains under the sieve, each dropped from ``rain.drop_height_d`` mean diameters
        above the heap's surface where it falls (the top of the settled grains within one
        diameter of its abscissa, as :meth:`update_height` found them; the ground where there
        are none): the impact speed is then the same at every size of heap, where a sieve
        above the apex would hit the lower flanks ever harder as the heap grows.  Every grain
        is checked for clearance against every grain, falling ones included (a low site lies
        far below the apex, where no height cut applies)."""
        new_p, new_r = [], []
        lift = (self.drop_d + 0.5) * self.d
        settled = self.settled if len(self.settled) == len(radius) else np.zeros(len(radius), bool)
        for x in self.rng.uniform(-self.half_width, self.half_width, self.sites):
            if len(new_r) >= limit:
                break
            under = settled & (np.abs(pos[:, 0] - x) < self.d)
            top = float(np.max(pos[under, 1] + radius[under])) if under.any() else self.y_ground
            self._try(x, self._radius(), pos, radius, new_p, new_r, max(top, self.y_ground) + lift - self.height)
        return np.array(new_p).reshape(-1, 2), np.array(new_r)
