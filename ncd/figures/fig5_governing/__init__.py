"""The §3 question beyond the paper: what governs indeterminacy, against Unger, Kertész & Wolf (2005)."""
