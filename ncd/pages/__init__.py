"""Layer 8, pages: what turns data into pages: notebook helpers, HTML rendering, the
reproduction page ``results/index.html`` (:mod:`ncd.pages.report`) and the config reference.
"""
