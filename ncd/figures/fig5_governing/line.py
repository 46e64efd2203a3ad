"""Figure 5: why the dispersion of a grain's acceleration is a line.

At a step whose converged NLGS runs reach several exact solutions
(:class:`ncd.shared.step_solutions.StepSolutions`): the contacts that switch status, the
dimension of the set keeping one solution's statuses (:func:`status_dimension`), the
clusters of grains that move differently, and the ranks of the acceleration field and of
one grain's cloud.  The hypothesis tested (:func:`line_analysis`, after Unger et al.'s
elementary clusters): a grain's cloud is a line when one isolated one-degree-of-freedom
cluster decides between the solutions; it has content from three solutions on.
"""
import numpy as np

from ncd.shared.slope_analysis import rigid_clusters
from ncd.solver.finish import status_system

STATUS_NAMES = ("open", "stick", "slide forward", "slide backward")


def switched_contacts(status):
    """Per contact: True when its status differs between any two solutions ``(S, kappa)``."""
    status = np.asarray(status)
    return (status != status[:1]).any(axis=0)


def _nullity(M, rel=1e-9):
    if M.shape[1] == 0:
        return 0
    if M.shape[0] == 0:
        return M.shape[1]
    s = np.linalg.svd(M, compute_uv=False)
    return int(M.shape[1] - np.sum(s > rel * max(s[0], 1e-300)))


def status_dimension(W, H, mu, status):
    """``(dim null K, velocity dimension)`` of the affine set of the statuses ``status``:
    impulses ``s = P x`` with ``K x = S^T (W P x + q) - S^T q`` unchanged; the velocity
    dimension counts the directions that move grains, ``dim null K - dim null (H P)``
    (``H P x = 0``: a self-stress, ``K x = 0`` with no grain moving)."""
    P, S = status_system(np.asarray(mu, float), np.asarray(status, np.int8))
    K = (S.T @ W @ P).toarray()
    HP = (H @ P).toarray()
    n_imp = _nullity(K)
    n_still = _nullity(HP) if n_imp else 0       # H P x = 0 implies K x = 0: self-stresses
    return n_imp, n_imp - n_still


def moving_clusters(delta, body_a, body_b, active, threshold):
    """Grains whose acceleration differs between solutions (``delta`` (S-1, n, 2): the
    other solutions minus the first; moving when some ``|delta| > threshold``) and the
    connected groups they form through ``active`` contacts between two moving grains.
    Returns ``(moving (n,) bool, labels (n,) int: group of each moving grain, -1 otherwise)``."""
    delta = np.asarray(delta, float)
    n = delta.shape[1]
    moving = (np.hypot(delta[..., 0], delta[..., 1]) > threshold).any(axis=0)
    a, b = np.asarray(body_a), np.asarray(body_b)
    inside = (b >= 0) & (b < n)
    links = np.zeros(len(a), bool)
    links[inside] = np.asarray(active, bool)[inside] & moving[a[inside]] & moving[b[inside]]
    labels = -np.ones(n, np.int64)
    if moving.any():   # components of the moving grains, numbered by their smallest grain
        labels[moving] = np.unique(rigid_clusters(n, a, b, links)[moving], return_inverse=True)[1]
    return moving, labels


def field_rank(accel, threshold):
    """Independent directions spanned by acceleration fields ``(S, n, 2)``: singular
    values of ``a_k - a_0`` above ``threshold`` (the same scale as the solution threshold)."""
    a = np.asarray(accel, float).reshape(len(accel), -1)
    if len(a) < 2:
        return 0
    s = np.linalg.svd(a[1:] - a[:1], compute_uv=False)
    return int(np.sum(s > threshold))


def cloud_rank(ax, ay, threshold):
    """Rank of a 2-D cloud of points: principal RMS extents above ``threshold`` (0 a point,
    1 a line, 2 an area); also returns ``(major, minor)``."""
    d = np.column_stack([ax, ay]) - np.array([np.mean(ax), np.mean(ay)])
    s = np.linalg.svd(d, compute_uv=False) / np.sqrt(max(len(d), 1))
    s = np.concatenate([s, np.zeros(2 - len(s))])
    return int(np.sum(s > threshold)), float(s[0]), float(s[1])


def line_analysis(accel, status, body_a, body_b, cloud, grain, threshold, W=None, H=None, mu=None):
    """Every measure of why a line, at one indeterminate step.

    ``accel`` (S, n, 2) the distinct solutions, most frequent first; ``status`` (S, kappa);
    ``cloud`` (runs, 2) the accelerations of ``grain``.  The cloud is predicted a line when
    the grain's cluster of differing grains has one degree of freedom.  With ``W, H, mu``
    the status dimensions of the first solution are added.  Returns a dict of numbers."""
    accel, status = np.asarray(accel, float), np.asarray(status)
    switched = switched_contacts(status)
    active = (status > 0).any(axis=0)
    moving, labels = moving_clusters(accel[1:] - accel[:1], body_a, body_b, active, threshold)
    rank_c, major, minor = cloud_rank(cloud[:, 0], cloud[:, 1], threshold)
    members = labels == labels[grain] if labels[grain] >= 0 else np.zeros(len(labels), bool)
    rank_k = field_rank(accel[:, members], threshold) if members.any() else 0
    out = {"n_switched": int(switched.sum()), "n_moving": int(moving.sum()), "n_clusters": int(labels.max() + 1),
           "field_rank": field_rank(accel, threshold), "cluster_size": int(members.sum()),
           "cluster_rank": rank_k, "cloud_rank": rank_c, "cloud_major": major, "cloud_minor": minor,
           "predicted_line": int(rank_k == 1)}
    out["hypothesis_holds"] = int(out["predicted_line"] == int(rank_c == 1))
    if W is not None:
        out["null_impulse"], out["null_velocity"] = status_dimension(W, H, mu, status[0])
    return out


__all__ = ["STATUS_NAMES", "switched_contacts", "status_dimension", "moving_clusters", "field_rank",
           "cloud_rank", "line_analysis"]
