"""Figure 2 (§3): the slope flow's investigated step (the flow itself is :mod:`ncd.shared.slope`),
its exact census of solutions, the page's sentences and claims."""
