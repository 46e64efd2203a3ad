"""Layer 6, scenes: the scenes and measurements that several figures share (the slope
flow, pile construction and its sources, static packings, cuts, frames), so that no
figure imports another figure's module.
"""
