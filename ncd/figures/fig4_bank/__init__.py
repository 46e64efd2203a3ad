"""The end of §5: cuts parallel to the free surface, the bank's stress and reciprocity."""
