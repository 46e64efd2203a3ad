"""Layer 3, solver: the core problem of one Contact Dynamics step.

Settings and result types (:mod:`.settings`), the packed problem (:mod:`.pack`), the
single-contact law (:mod:`.single_contact`), the NLGS kernels (:mod:`.kernels`), and
the methods composed by the front door :mod:`.nlgs`: the stopping rule
(:mod:`.convergence`), Anderson acceleration, local exact solves, the active-set
finishing stage and Lemke's method (:mod:`.lcp`). Variants are leaves; the front door
composes them and nothing imports it back.
"""
