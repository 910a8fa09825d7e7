"""Independent generator for the validation harness (scripts/validate_independent.py).

Written from the paper's equations (2.3)/(3.1), not from the project's C++ simulator: the full
equations are integrated in f, f', g, g' by scipy's solve_ivp (not the project's van der Pol RK4),
and the averaged model is obtained by averaging the same forces numerically over one period
(quadrature), not from the closed-form columns of (2.5)/(3.2). Units SI; tilde coefficients
(divided by omega) are stored under the plain name, as in the tool's JSON.
"""
