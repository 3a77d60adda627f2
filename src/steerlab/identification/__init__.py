"""Identification of Nomoto, Norrbin and Bech models from trial records (thesis Sec. 2.5).

:mod:`.record` reads a record (CSV); :mod:`.spiral` finds the steady turns and fits the
(reversed) spiral polynomial by least squares (Sec. 2.5.2); :mod:`.response` simulates a
model's response to the recorded rudder with the engine's own plant step; :mod:`.fit` adjusts
the dynamic parameters by nonlinear least squares over that response (Sec. 2.5.3, criterion
2.57) and reports confidence intervals from the Jacobian.
"""
