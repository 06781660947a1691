"""The paper's reproduction: its scenarios (section 4), its figures and its claims
(conclusions 1-3) checked against the simulations (``tailbeam reproduce``).
"""
