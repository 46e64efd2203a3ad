"""§2: work-precision, NLGS residual and distance to a reference against run time and sweeps."""
