"""Layer 8, studies: the solver itself rather than a figure of the paper.

* :mod:`ncd.studies.scenes` -- small scenes built here (not taken from the figures);
* :mod:`ncd.studies.stability` -- stability on stiff and extreme cases, Contact Dynamics
  against the soft-contact baseline :mod:`ncd.dynamics.md`;
* :mod:`ncd.studies.work_precision` -- error against run time, NLGS at one step and time integration;
* :mod:`ncd.studies.bench`, :mod:`ncd.studies.finish_bench` -- benchmarks of the solver;
* :mod:`ncd.studies.peer` -- ncd side by side with pymunk.
"""
