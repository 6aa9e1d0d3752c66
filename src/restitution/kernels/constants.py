"""Numbers more than one kernel uses, each defined once with the reason for its value.

A number tuned for one kernel alone stays beside that kernel; a number two kernels share, or one
decision taken for two kernels, lives here, so that changing it changes it everywhere.
"""

EPS = 2.0**-52  # unit round-off of float64 (2.220446049250313e-16)

# The contact budget (max_events) of every entry point where none is given: solve, solve_many,
# the CLI, the analyses; the chain kernel's work budget is sized for it (exact_chain.WORK_EVENTS).
# Here, not in model.ranges, so that the CLI's --help reads it without importing numpy.
MAX_EVENTS_DEFAULT = 100_000

# The exact kernels' round-off bound per contact, in ulps: the floor of OUT_ERR of the
# closed-form two-mass walk (rigid2) and of the chain kernel (times the eigenbasis condition).
ROUNDOFF_ULPS = 64.0

# The exact kernels' energy account must close to this (fractions of the initial energy), else
# STATUS_ENERGY; the chain kernel allows its own larger error bound where it has one.
ENERGY_TOL = 1e-9

# Chatter and its sticking limit (rigid wall with a dashpot; kernels/rigid2.py and
# kernels/exact_chain.py): after STICK_AFTER contacts, a contact slower than the cut-off under a
# compressive force continues as sticking. Shorter chatters end by themselves within a few
# thousand contacts and are finished exactly (cutting them costs up to ~1e-5 in the COR).
STICK_AFTER = 2000
# The cut-off moves the COR by about 1e-3 v^2 where the chatter would go on (cut-offs 1e-1, 1e-2,
# 1e-3 moved it by 1e-5, 4e-8, 8e-10 against 1e-4, alpha 20..50, xi 1..2), and the kernels report
# v^2 as its bound. (Not a bound everywhere: a chatter that would end by itself soon after the
# cut is off by more; N = 4, alpha = 20, xi = 0.3 sticks after 2001 contacts where the exact
# sequence ends after 2095, COR off by 6.6e-6 = 1.5 v^2.) The smaller the cut-off the better,
# but chatter speeds decay only like 1/k (k: the contact index), so a cut-off 3 times smaller
# needs about 3 times the contacts. Each kernel takes the smallest its cost per contact affords:
# - the closed-form two-mass walk (rigid2) costs microseconds per contact: 1e-3 is reached
#   within the default event budget on the grid alpha 5..200, xi 0.05..3 (1e-4 was not: alpha
#   150 and 200 at xi = 0.5 needed more than 100,000 contacts), and 3e-3 would only raise its
#   bound (largest OUT_ERR on that grid 1e-6 -> 9e-6);
V_STICK_RIGID2 = 1e-3
# - the chain kernel locates every contact of N >= 3 masses over its modes, against its work
#   budget (exact_chain.WORK_MAX) and the event budget: on that grid for N = 3, 4, 5, 8, 16, 32,
#   64, 128 (160 scenes), 3e-3 leaves 19 unfinished (N >= 32), 1e-3 would leave 30 (N >= 16).
V_STICK_CHAIN = 3e-3
