"""Layer 8, studies: the solver itself: stability on stiff and extreme cases and
work-precision (error against run time), Contact Dynamics against the soft-contact
molecular-dynamics baseline :mod:`ncd.dynamics.md`.

* :mod:`ncd.studies.scenes` -- small scenes built here (not taken from the figures);
* :mod:`ncd.studies.stability` -- the stability table;
* :mod:`ncd.studies.work_precision` -- NLGS at one step and time integration.
"""
