"""Layer 5, shared: what several figures share, so that no figure imports another figure's
package: the slope flow (Figures 2 and 5) with its frames, analysis and exact step solutions;
the pile (Figures 4 and its history and bank): sources, construction, cuts; the verdict record
that every figure's claims return.  A module with one user lives in that figure's package.
"""
