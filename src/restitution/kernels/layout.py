"""Shared layout of kernel outputs: one float64 row per scene, one row per contact in a history.

Every kernel returns ``out`` (length ``N_OUT``) and fills up to ``hist.shape[0]`` rows of ``hist``
(shape ``(rows, N_HIST)``; pass a ``(0, N_HIST)`` array to record nothing). Units are the
non-dimensional ones of docs/physics.md: m1 = 1, V0 = 1, omega = 1, so a kernel time *is* omega*t.
"""

# Columns of ``out``.
OUT_COR = 0  # centre-of-mass velocity after the final separation / V0
OUT_NCOL = 1  # number of separate contact intervals
OUT_TCOL = 2  # omega * (final separation time - first contact time)
OUT_ETRANS = 3  # final translational kinetic energy / initial kinetic energy (= cor**2)
OUT_EVIB = 4  # final vibrational energy (relative kinetic + structural springs) / initial
OUT_EDISS = 5  # energy dissipated (dashpot, plastic contact) / initial, integrated independently
OUT_STATUS = 6  # one of the STATUS_* codes below
OUT_NEVENTS = 7  # number of history rows the kernel wanted to write (may exceed hist rows)
OUT_ERR = 8  # the method's own error estimate for cor (0 where exact up to round-off)
OUT_FLAGS = 9  # bit set of FLAG_* below (how the result was obtained)
N_OUT = 10

# Columns of ``hist`` (one row per contact interval; for a rigid wall t_start == t_end).
H_TSTART = 0  # omega * t at the start of the contact
H_TEND = 1  # omega * t at separation
H_VIN = 2  # m1 velocity / V0 at the start of contact (<= 0: towards the wall)
H_VOUT = 3  # m1 velocity / V0 at separation (>= 0)
H_XMAX = 4  # largest penetration x = -u1 during the contact, in V0/omega units (0 if rigid)
H_IMPULSE = 5  # momentum given by the wall during the contact / (m1 V0)
N_HIST = 6

# Status codes (restitution.solvers.result.STATUS names them).
STATUS_OK = 0
STATUS_EVENT_BUDGET = 1  # more contacts than max_events: the sequence was NOT finished
STATUS_ENERGY = 2  # the independent energy account does not close within tolerance
STATUS_ILL_CONDITIONED = 3  # an eigenbasis too ill-conditioned for a trustworthy closed form
STATUS_NONCONVERGED = 4  # an event root search did not converge
STATUS_PERMANENT_CONTACT = 5  # m1 never leaves the wall (proven): cor = 0, omega_t_col = inf
STATUS_WORK_BUDGET = 6  # the scene's work budget (operations, not time) ran out: NOT finished
STATUS_INVALID = 7  # parameters outside what the kernel handles (NaN, inf, non-positive mass...)
STATUS_NOT_RUN = 8  # a batch row the kernel never finished (rows start with it, NaN elsewhere)
# the sequence finished, but the run of the method's other setting that checks it did not: no
# error estimate (inf); set by restitution.solvers.numerical, never by a kernel
STATUS_UNCHECKED = 9

# Bits of out[OUT_FLAGS].
FLAG_STICKING = 1  # a Zeno chatter was continued by its sticking limit (method impulsive+sticking)
FLAG_RIGID_LIMIT = 2  # a very stiff contact spring was solved as its rigid limit (OUT_ERR: bound)
FLAG_EXTRAPOLATED = 4  # ... as its rigid limit corrected by two finite-stiffness runs (sqrt(beta))
# A search row (``exact_chain.solve_chain_batch(check=False)``): the first run alone, no replica
# check, so OUT_ERR is only the kernel's own bound and the row is no checked result. Optimisers
# read its COR (identical, bit for bit, to the checked row's) and never show the row.
FLAG_UNCHECKED = 8
# A row whose dashpots were scaled by 1 -+ d and 1 -+ 2 d around a near-defective phase (below)
# and averaged (``solvers.exact.bracketed``): the method gains ``+critical-bracket``.
FLAG_CRITICAL_BRACKET = 16
# A phase's eigenbasis is near-defective: two of its eigenvalues within DEFECT_REL of each other
# and a condition number above COND_DEFECT (``exact_chain``), as where a damped mode turns from
# oscillating to creeping (critical damping). Its closed form loses about eps * cond.
FLAG_NEAR_DEFECTIVE = 32

# Statuses of a row that is not a finished result. Before a user sees such a row its COR,
# duration and energies are voided (NaN, ``void_unfinished``); the count of contacts reached
# stays. Not in the list: energy_account_open keeps its numbers (the plastic law with eta > 1 is
# not passive, and the flag says the account is open, not that the run stopped), and
# permanent_contact is a finished result (cor = 0, omega_t_col = inf), and so is an unchecked
# one (its COR is the finished run's, without an error estimate).
UNFINISHED = (
    STATUS_EVENT_BUDGET,
    STATUS_ILL_CONDITIONED,
    STATUS_NONCONVERGED,
    STATUS_WORK_BUDGET,
    STATUS_INVALID,
    STATUS_NOT_RUN,
)
# A linear chain is passive: an open energy account there means the result is wrong, not that
# energy came from a law, so exact (linear) rows void it too.
UNFINISHED_PASSIVE = (*UNFINISHED, STATUS_ENERGY)
VOIDED = (OUT_COR, OUT_TCOL, OUT_ETRANS, OUT_EVIB, OUT_EDISS)


def void_unfinished(out, passive: bool = False):
    """Set COR, duration and energies of the unfinished rows of ``out`` (a block of kernel rows,
    2-D) to NaN, in place; a NaN status counts as unfinished, and so does an open energy account
    of a ``passive`` (linear) scene. Returns ``out``."""
    import numpy as np

    status = out[:, OUT_STATUS]
    bad = np.isin(status, UNFINISHED_PASSIVE if passive else UNFINISHED) | np.isnan(status)
    if bad.any():
        out[np.ix_(bad, VOIDED)] = np.nan
    return out
