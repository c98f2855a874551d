#!/usr/bin/env python3
"""Coefficients of atan2_in_double (lib/warpcheck/core.h): atan(t) = t P(t^2) on |t| <= tan(pi/8), P of degree 10.

P is mpmath's Chebyshev fit (near minimax) of atan(sqrt(s)) / sqrt(s) on [0, tan(pi/8)^2]; its relative error is
printed. Needs python3-mpmath. Usage: scripts/fit_arctangent.py
"""
import argparse

import mpmath as mp

argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter).parse_args()

mp.mp.dps = 50
s_max = mp.tan(mp.pi / 8) ** 2


def atan_over_t(s):
    return mp.mpf(1) if s == 0 else mp.atan(mp.sqrt(s)) / mp.sqrt(s)


poly, err = mp.chebyfit(atan_over_t, [0, s_max], 11, error=True)
print(f"relative error of the fit: {mp.nstr(err, 3)}")
for k, c in enumerate(reversed(poly)):  # c_0 first
    print(f"c{k} = {mp.nstr(c, 20, strip_zeros=False)}")
