"""Figure 1 (§1): the wedged disc below two fixed discs, its one-step ensemble and the friction sweep."""
