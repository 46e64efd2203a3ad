"""Layer 7, studies: the solver itself rather than a figure of the paper.

* :mod:`ncd.studies.cases` -- small scenes built here (not taken from the figures);
* :mod:`ncd.studies.stability.measure` -- stability on stiff and extreme cases, Contact Dynamics
  against the soft-contact baseline :mod:`ncd.dynamics.md`;
* :mod:`ncd.studies.error_vs_runtime.measure` -- error against run time, NLGS at one step and time integration;
* :mod:`ncd.studies.bench.solver`, :mod:`ncd.studies.bench.finish` -- benchmarks of the solver;
* :mod:`ncd.studies.bench.peer` -- ncd side by side with pymunk.
"""
