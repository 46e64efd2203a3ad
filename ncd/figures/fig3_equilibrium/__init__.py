"""Figure 3 (§4): NLGS clouds of a packing at rest against the exact projections of A ∩ C."""
