"""Layer 6, figures: one package per figure of the paper, named by its config key.

Each package owns its computation (``measure.py``, ``exact.py``, ... as the figure needs),
its plots (``plots.py``), the sentences its page prints (``page.py``) and the judging
functions of its rows on the index (``claims.py``, a table ``MEASURES``).  Packages do not
import each other (an import-linter ``independence`` contract); what two figures share
lives in :mod:`ncd.shared`.  The workflow reads a rule's code inputs from the imports of
its script, so an edit of one figure's computation reruns that figure's jobs only.
"""
