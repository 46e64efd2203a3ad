"""Layer 4, dynamics: Moreau–Jean time stepping (:mod:`.stepper`), ensembles of NLGS
runs on one step (:mod:`.explore`), and the Cundall–Strack MD baseline (:mod:`.md`).
"""
