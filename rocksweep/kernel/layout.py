"""What crosses into the jitted kernel: index constants of the plain float64 arrays.

Numba reads module-level ints as compile-time constants, so these cost nothing in the loop.
The kernel takes one parameter row per point (``PAR_*``) and fills one result row
(``OUT_*``; the loop keeps its event counters there as it runs); single runs also fill a history
buffer (``HIST_*`` columns). Inside the loop the state is a 6-tuple (``Y_*`` slots; 9 slots for the
sliding base). All
quantities are SI with m = 1 kg, g = 9.81 m/s^2 and p = 1 rad/s (see ``rocksweep.physics.bodies``),
so times are p*t.
"""

from rocksweep.vocab import ground as _ground
from rocksweep.vocab import laws as _laws
from rocksweep.vocab import outcomes as _out
from rocksweep.vocab import phases as _phases
from rocksweep.vocab import settings as _settings

# --- parameter row ---------------------------------------------------------------------
PAR_M = 0  # top mass m [kg]
PAR_MA = 1  # base mass m_A [kg]
PAR_IA0 = 2  # I_A + m_A R_A^2: base inertia about a corner [kg m^2]
PAR_IAH = 3  # I_A + m_A h_A^2: base inertia about the base's mid point (eq. 1) [kg m^2]
PAR_H = 4  # h [m]
PAR_HA = 5  # h_A [m]
PAR_B = 6  # b [m]
PAR_G = 7  # g [m/s^2]
PAR_K = 8  # k [N/m] (unused by the rigid kernel)
PAR_C = 9  # c [N s/m]
PAR_MTOT = 10  # M = m + m_A [kg]
PAR_HCG = 11  # h_cg [m]
PAR_IO = 12  # I_O about a corner with u = 0 [kg m^2]
PAR_AMP = 13  # pulse amplitude A [m/s^2] (signed)
PAR_OMEGA = 14  # pulse frequency omega [rad/s]
PAR_SHAPE = 15  # SHAPE_* code (``vocab.ground.SHAPE_CODE``)
PAR_TPULSE = 16  # end of the ground motion [s]: the pulse's duration (its cycles, Ricker's and
#                  MP's own: ``vocab.ground.pulse_duration``), a record's length; 0 for FREE
PAR_LAM = 17  # lam (Pi10)
PAR_DT = 18  # RK4 step once the ground is still (after the pulse or record) [s]
PAR_TOL = 19  # event tolerance: width of the final bracket on time [s]
PAR_TEND = 20  # horizon: absolute end time [s]
PAR_MAXSTEPS = 21  # cap on RK4 evaluations (regular + event) per run
PAR_MAXEVENTS = 22  # cap on impacts + uplifts per run
PAR_RESTRATE = 23  # post-impact |theta'| below which the body settles [rad/s]
PAR_THETA_OVER = 24  # |theta| at which the body lies on its side: pi/2 [rad]
PAR_ROOT = 25  # event root finder: ROOT_BISECT, ROOT_ILLINOIS or ROOT_HERMITE
PAR_THETA0 = 26  # initial theta [rad] (0: full contact; > 0 rocking on corner +1, < 0 on -1)
PAR_THETA_DOT0 = 27  # initial theta' [rad/s] (from theta = 0: rocking on its sign's corner)
PAR_MU = 28  # friction coefficient of the base on the ground (NaN: none given)
PAR_GAMMA = 29  # Mavroeidis-Papageorgiou pulse: oscillation parameter gamma (>= 1)
PAR_NU = 30  # Mavroeidis-Papageorgiou pulse: phase nu [rad]
PAR_AMP_NORM = 31  # Mavroeidis-Papageorgiou pulse: 1/r_max, so that A is its peak |xg''|
PAR_REC_DT = 32  # record: sample interval in kernel time, p * DT [s] (0: not a record)
PAR_REC_H = 33  # record: RK4 step while it acts, PAR_REC_DT / m (m >= 1 an integer) [s]
PAR_ROT_STEP = 34  # largest rotation of one rocking step [rad] (0: no such limit)
PAR_LAW = 35  # impact law, read at impacts: LAW_EQ1 (eq. 1), LAW_LOCKED, LAW_CONSTANT
PAR_E = 36  # LAW_CONSTANT's coefficient of restitution (unused by the other laws)
PAR_E_FACTOR = 37  # multiplies the law's e (1: the law's own e)
PAR_DT_ON = 38  # RK4 step while the ground moves, t < PAR_TPULSE (<= PAR_DT) [s]
PAR_ALPHA_REF = 39  # alpha_ref: alpha_cg of a flexible body, alpha of a block [rad]
PAR_CLOSE = 40  # OUT_MARGIN below which the run is near its threshold (``numerics.
#                 close_band``; certified after the kernel, ``rocksweep.compute.certify``)
#                 [alpha_ref]
PAR_U0 = 41  # initial u [m] (flexible bodies; with PAR_THETA0, PAR_THETA_DOT0 the state at t = 0)
PAR_U_DOT0 = 42  # initial u' [m/s]
# 1: a run goes on past its bound (a rigid body's ``rigid_bounded``, a flexible one's
# ``flexible_bounded``) to rest, for a history to show (free rocking, a calibration) or a
# test to follow the rocking to rest; the bound still decides the class (STATUS_BOUNDED,
# never flagged at the horizon). 0: the run ends at the bound. (A flexible body's bound
# is tested by the outcome-only variants alone: the others go on to rest anyway.)
PAR_TO_REST = 43
# The vertical ground acceleration a_v (positive up; the vertical variants only, else 0):
# while the ground moves, gravity is g + a_v(t) (docs/vertical.md)
PAR_V_AMP = 44  # a_v per unit of the vertical's shape [m/s^2]: a harmonic's amplitude, or
#                 a record's scale |xg''|/shape, the horizontal's (one factor for both)
PAR_V_OMEGA = 45  # the harmonic's angular frequency [rad/s] (p = 1)
PAR_V_PHASE = 46  # the harmonic's phase [rad]: a_v = PAR_V_AMP sin(PAR_V_OMEGA t + phase)
PAR_V_REC = 47  # index in the row of the vertical record's first sample (0: the harmonic)
PAR_T_AIR = 48  # first time g + a_v <= 0 [s] (inf: never): the run stops there, airborne
# The sliding base (CONTACT_SLIDE, docs/sliding.md): PAR_MU is then its kinetic friction
# coefficient, this its static one (>= PAR_MU; NaN without mu)
PAR_MU_STATIC = 49
# How long the top mass's spring remembers its past while the base rocks [s], p = 1
# (``numerics.spring_memory``; 0 for a rigid body). Not read by the kernel: the
# certification probes the near-misses of a spring that rings long further
# (``compute.certify``)
PAR_MEMORY = 50
# The tilt theta_r [rad] at which the ridge of a flexible body's potential energy peaks
# (``equations.ridge_energy``: the least V over u at a tilt; the overturning saddle's
# energy is W(theta_r)). Once the ground is still, a run inside the peak (|theta| <
# theta_r) whose energy T + V is below W(min(theta_max, theta_r)) can neither overturn
# nor tilt past its theta_max again: it is decided (STATUS_BOUNDED,
# ``transitions.flexible_bounded``). NaN: no such bound (a rigid body, which has
# ``rigid_bounded``; an impact law that may gain energy). Filled by ``physics.points``
# (``ridge_column``, ``impacts_lose``)
PAR_RIDGE = 51
N_PAR = 52
# A record's row is longer: its samples xg''/PGA (float64[npts], in [-1, 1]) follow the
# N_PAR parameters, PAR_REC = N_PAR the first (``points.with_record``). With a vertical
# record: then one copy of the last horizontal sample (the horizontal's reader clamps at
# the row's end: past its last sample it sees a flat segment) and the vertical's samples
# a_v/(g PGA) on the horizontal's times, from PAR_V_REC = PAR_REC + npts + 1.
PAR_REC = N_PAR

SHAPE_SINE = _ground.SHAPE_CODE[_ground.SINE]
SHAPE_COSINE = _ground.SHAPE_CODE[_ground.COSINE]
SHAPE_RICKER = _ground.SHAPE_CODE[_ground.RICKER]
SHAPE_MP = _ground.SHAPE_CODE[_ground.MP]
SHAPE_RECORD = _ground.SHAPE_CODE[_ground.RECORD]
LAW_EQ1 = _laws.LAW_CODE[_laws.EQ1]
LAW_LOCKED = _laws.LAW_CODE[_laws.LOCKED]
LAW_CONSTANT = _laws.LAW_CODE[_laws.CONSTANT]
ROOT_BISECT = _settings.ROOT_CODE[_settings.BISECTION]
ROOT_ILLINOIS = _settings.ROOT_CODE[_settings.ILLINOIS]
ROOT_HERMITE = _settings.ROOT_CODE[_settings.HERMITE]

# --- result row ------------------------------------------------------------------------
OUT_OUTCOME = 0  # OUTCOME_* code
OUT_STATUS = 1  # bit set of STATUS_*
OUT_IMPACTS = 2
OUT_UPLIFTS = 3
OUT_THETA_MAX = 4  # max |theta| [rad]
OUT_T_OVERTURN = 5  # [s] = p*t, NaN if none
OUT_T_END = 6  # time the run stopped [s]
OUT_STEPS = 7  # regular RK4 steps
OUT_EVENT_STEPS = 8  # RK4 re-integrations spent locating events
OUT_T_FIRST_IMPACT = 9  # [s], NaN if none
OUT_W_IN = 10  # work of the ground motion [J] (energy variants only, else NaN)
OUT_D_DAMP = 11  # energy dissipated by the damper [J] (energy variants only)
OUT_E_IMPACT = 12  # energy lost in impacts, net [J] (energy variants only)
OUT_E_GAINED = 13  # energy gained in impacts with E_d < 0 [J] (energy variants only)
OUT_N_GAINING = 14  # impacts that gained energy (energy variants only)
OUT_E_END = 15  # mechanical energy at the end, relative to rest [J] (energy variants)
OUT_E_MAX = 16  # largest restitution seen
OUT_CONTACTS = 17  # returns to full contact (e <= 0 or settling below the rest rate)
OUT_HIST_ROWS = 18  # rows written to the history buffer
OUT_MU_REQ = 19  # friction demand max |H|/N over the run (contact variants, else NaN)
OUT_N_MIN = 20  # smallest normal reaction N/(M g) over the run (contact variants)
OUT_IMPULSE_MAX = 21  # largest |horizontal|/vertical impulse of an impact (contact variants)
OUT_MARGIN = 22  # closest approach of the free rocking to the overturning saddle
#                  [alpha_ref] (inf: never near it): a small value is a close call
OUT_T_CLOSE = 23  # last time [s] the free rocking came within PAR_CLOSE of the saddle
#                   (NaN: never): after it the run decided nothing near its threshold
OUT_REFINE_EVALS = 24  # RK4 evaluations (regular + event) of the certification's runs of
#                        this point, counted in OUT_STEPS/OUT_EVENT_STEPS too (0 from the
#                        kernel; set by ``rocksweep.compute.certify``)
# The sliding base (CONTACT_SLIDE only; NaN from the no-slip model)
OUT_SLIDE_MAX = 25  # max |x| over the run [m]: how far the base slipped along the ground
OUT_SLIDE_FINAL = 26  # |x| at the end [m]
OUT_REGIME = 27  # the phases visited: bit (1 << PHASE_CODE) of each (``vocab.phases``)
OUT_D_FRIC = 28  # energy dissipated by friction [J] (energy variants, else NaN)
OUT_GRAZE = 29  # closest a rocking arc came to an impact it did not make while the ground
#                 moved: the least minimum of s theta inside a step where theta fell and
#                 rose again without reaching 0 (the step's cubic Hermite interpolant)
#                 [alpha_ref] (inf: no such dip). A small one that moves between runs is a
#                 graze the class may hang on (``rocksweep.compute.certify``)
OUT_MODE_GRAZE = 30  # how near the run came to the other mode [alpha_ref]: without an
#                 impact, the least dip of s theta toward 0 (as OUT_GRAZE, at any time);
#                 with impacts, the deepest one's depth, (theta'/alpha_ref)^2 / 2 at it
#                 (a finer run that missed them all would fall in mode 2). inf: no dip
OUT_LIFT_GRAZE = 31  # how near the body came to uplifting before its first uplift, in full
#                 contact: the least minimum of the uplift function M g b - s Q inside a
#                 step where it fell and rose again without reaching 0 (the step's cubic
#                 Hermite interpolant, as OUT_GRAZE), over M g b at PAR_G (a base that
#                 slides: at rest only, stuck and flat). inf: no such dip. A mode 2 that
#                 came this near an earlier uplift hangs on it: a finer run may uplift by a
#                 hair there and impact, and fall in mode 1 (``certify.mode_close``)
OUT_UNSPLIT = 32  # the longest phase (event to event) that ended inside the first step
#                   after its start, over the step then in effect (dt_on while the ground
#                   moves, dt after), among those before the run's last approach within
#                   PAR_CLOSE of the saddle (OUT_T_CLOSE), or before its fall: a phase no
#                   step split, integrated alike at every step longer than it (0: none; a
#                   base that slides takes none). A finer run's above
#                   ``numerics.UNSPLIT_SHARE`` voids its agreement with the coarser one
#                   (``rocksweep.compute.certify.unsplit``)
OUT_SHALLOW = 33  # the shallowest impact made while the ground moved: the least depth,
#                   (theta'/alpha_ref)^2 / 2 at it (``loop.impact_depths``) [alpha_ref]
#                   (inf: none). A finer run may miss an impact this shallow, the mirror
#                   of OUT_GRAZE's, and take another path (``certify.shallow_close``)
OUT_LIFT_ANGLE = 34  # a base that may slide: where its rocking corner's normal force fell
#                   to zero (STATUS_LIFTS_OFF) or within ``slide_loop.LIFT_NEAR`` M g of
#                   it in slide-rock, the least |theta| / alpha_ref there after the ground
#                   stopped, 0 while it moved (inf: never). One far past the saddle is a
#                   falling body's: it changes no class (``certify.lifted_off``)
N_OUT = 35

# --- state tuple y (the loop's 6 slots, a UniTuple(float64, 6)) ----------------------------
Y_THETA = 0  # theta [rad] (0 in full contact)
Y_THETA_DOT = 1  # theta' [rad/s]
Y_U = 2  # u, the top mass's lateral displacement [m] (0 for a rigid body)
Y_U_DOT = 3  # u' [m/s]
Y_W_IN = 4  # work of the ground motion so far [J] (energy variants; else stays 0)
Y_D_DAMP = 5  # energy dissipated by the damper so far [J] (energy variants; else stays 0)
# the sliding base's three more (``slide_loop``: a UniTuple(float64, 9))
Y_X = 6  # x, the sliding displacement [m]
Y_X_DOT = 7  # x' [m/s]
Y_D_FRIC = 8  # energy dissipated by friction so far [J] (energy variants)

# --- history columns ---------------------------------------------------------------------
HIST_T = 0
HIST_THETA = 1
HIST_THETA_DOT = 2
HIST_U = 3
HIST_U_DOT = 4
HIST_PHASE = 5  # -1 / +1 rocking corner, 0 full contact
HIST_E = 6  # mechanical energy relative to rest [J]
HIST_W_IN = 7
HIST_D_DAMP = 8
HIST_E_IMPACT = 9
HIST_XG = 10  # ground acceleration [m/s^2]
# the sliding base's (CONTACT_SLIDE; the no-slip model leaves them unwritten)
HIST_X = 11  # the sliding displacement x [m]
HIST_CONTACT = 12  # the contact phase's code (``vocab.phases``: rest, slide, rock, slide-rock)
HIST_D_FRIC = 13  # energy dissipated by friction so far [J]
N_HIST = 14

# --- contact phases (``vocab.phases``; the sliding base, docs/sliding.md) -----------------
PHASE_REST = _phases.PHASE_CODE[_phases.REST]
PHASE_SLIDE = _phases.PHASE_CODE[_phases.SLIDE]
PHASE_ROCK = _phases.PHASE_CODE[_phases.ROCK]
PHASE_SLIDE_ROCK = _phases.PHASE_CODE[_phases.SLIDE_ROCK]

# --- outcome and status codes ----------------------------------------------------------
# (codes and words: ``rocksweep.vocab.outcomes``)
OUTCOME_NOT_RUN = _out.OUTCOME_NOT_RUN
OUTCOME_SAFE = _out.OUTCOME_SAFE
OUTCOME_MODE1 = _out.OUTCOME_MODE1  # overturned after one or more impacts
OUTCOME_MODE2 = _out.OUTCOME_MODE2  # overturned without impact

STATUS_REST = _out.STATUS_BIT["rest"]
STATUS_HORIZON = _out.STATUS_BIT["horizon"]  # horizon reached before the outcome was decided
STATUS_STEP_CAP = _out.STATUS_BIT["step_cap"]
STATUS_EVENT_CAP = _out.STATUS_BIT["event_cap"]
STATUS_NONFINITE = _out.STATUS_BIT["nonfinite"]
STATUS_HIST_FULL = _out.STATUS_BIT["history_full"]
STATUS_ENERGY_GAIN = _out.STATUS_BIT["energy_gain"]
# chattering ended in full contact through the rest-rate rule (no proof of rest: a run that
# then ends early is not flagged REST)
STATUS_SETTLED = _out.STATUS_BIT["settled"]
STATUS_OVERTURNED = _out.STATUS_BIT["overturned"]
STATUS_E_ABOVE_1 = _out.STATUS_BIT["e_above_1"]  # at least one impact had e > 1
# safe proven after the pulse (early exit; impacts counted up to there): a rigid body below
# its overturning energy, |e| <= 1 (``rigid_bounded``), or a flexible body below its ridge
# (``flexible_bounded``, outcome-only runs)
STATUS_BOUNDED = _out.STATUS_BIT["bounded"]
STATUS_SLIDES = _out.STATUS_BIT["slides"]
STATUS_LIFTS_OFF = _out.STATUS_BIT["lifts_off"]
# g + a_v <= 0: the ground falls faster than gravity, the body leaves it (outside the model)
STATUS_AIRBORNE = _out.STATUS_BIT["airborne"]
STATUS_SLID = _out.STATUS_BIT[_out.SLID]  # the base slipped (CONTACT_SLIDE)
# Set after the kernel, by the certification of close calls (``rocksweep.compute.certify``)
STATUS_REFINED = _out.STATUS_BIT["refined"]  # a close call, re-run finer until stable
STATUS_UNCERTIFIED = _out.STATUS_BIT["uncertified"]  # still changed at the last refinement
# A run with any of these is not a reliable classification: "flagged".
STATUS_FLAGGED = _out.FLAGGED

# --- kernel variants (compile-time flags) -----------------------------------------------
KIND_FLEXIBLE = 0
KIND_FLEXIBLE_UNDAMPED = 1
KIND_RIGID = 2
LEVEL_OUTCOME = 0  # outcome and summary metrics only
LEVEL_ENERGY = 1  # + energy accounting
LEVEL_CONTACT = 3  # + energy accounting + ground reactions (outputs.contact)
# (a single run with its time history: ``point_kernel``, not a level of the chunk kernels)
# ground kinds (``ground.GROUNDS``): the paper's sine and cosine; every horizontal shape and
# records; those with a vertical component
GROUND_PULSE = 0
GROUND_ANY = 1
GROUND_VERTICAL = 2
# contact models (``variants.CONTACTS``): how the body touches the ground; the paper's:
# rocking on a corner or in full contact, never sliding; the base that may slide, on a
# ground with Coulomb friction (a scene's body.mu: docs/sliding.md)
CONTACT_NOSLIP = 0
CONTACT_SLIDE = 1
