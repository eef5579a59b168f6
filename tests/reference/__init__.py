"""The NumPy reference (epc_fast.reference): the model's formulas and its sensitivities against
known values and mpmath."""
