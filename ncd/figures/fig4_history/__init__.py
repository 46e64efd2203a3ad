"""Figure 4 beyond the paper (§5): ensembles of piles built by two construction histories."""
