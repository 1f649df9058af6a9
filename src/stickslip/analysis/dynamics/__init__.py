"""Methods that drive the engine of eqs. (1) and (4) or linearise its equations: linear
stability (eqs. 2, 5; Fig. 4) from the pieces' Jacobian, the slip in the limit V -> 0 (eq. 3;
Fig. 3), the single block's hysteresis, the largest Lyapunov exponent on the grid and of the
flow, finite-size exponents, decorrelation of slip sequences and its threshold, the further
tests of stable chaos, and the runs that stop once their order parameter is measured."""
