"""A scan's reductions, folded chunk by chunk: the summaries and fractions (``summaries``),
histograms and quantiles (``histograms``), the best points (``best``), the groups they are kept
per (``groups``), the replicates' standard errors (``replicates``) and the accuracy targets
that size a scan (``targets``).
"""
