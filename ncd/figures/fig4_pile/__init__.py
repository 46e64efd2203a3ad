"""Figure 4 (§5): the pile poured from a point source, the force across a vertical cut, its cloud,
exact sets and the ground pressure."""
