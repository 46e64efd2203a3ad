"""Layer 4, exact: the solution set A ∩ C of an equilibrium problem, computed exactly
(polygons, the force polytope by LP, exact ranges with HiGHS).
"""
