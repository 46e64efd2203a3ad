"""Layer 3, solver: the core problem of one Contact Dynamics step.

Settings and result types (:mod:`.settings`), the packed problem (:mod:`.pack`), the
single-contact law (:mod:`.single_contact`), the NLGS kernels (:mod:`.kernels`), and
the methods composed by the front door :mod:`.nlgs`: the stopping rule
(:mod:`.convergence`), Anderson acceleration, local exact solves, the active-set
finishing stage and Lemke's method (:mod:`.lcp`). The front door composes the variants;
none of them imports it.
"""
