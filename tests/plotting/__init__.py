"""The figures (epc_fast.plotting): the paper's EPC curves, what limits each design, the text
on figures."""
