"""How a scan draws its points: the design space (``space``), the distributions a parameter
takes (``distributions``), the random streams of the draw contract (``streams``), plain Monte
Carlo or scrambled Sobol'-sequence points in replicates (``qmc``) and the parameters' domains
(``domains``).
"""
