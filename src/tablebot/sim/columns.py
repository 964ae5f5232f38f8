"""Column layouts of the simulator's per-robot arrays (state, parameters, history), shared by all sim modules.

Every robot is one row of a float64 array; these integers name the columns, so the compiled
physics core, the runner and the plots agree on one layout without passing dictionaries around.
"""

# --- state S[i, :] (one row per robot) -----------------------------------------------------------
X, Y, TH = 0, 1, 2  # pose: metres, metres, radians (counter-clockwise from +x, never wrapped)
V_R, V_L = 3, 4  # wheel surface speeds after the motor lag, m/s
ENC_R, ENC_L = 5, 6  # encoder pulses counted since the start (fractional accumulator)
PUL_R, PUL_L = 7, 8  # whole pulses in the last tick
SOC, VBAT, AMPS = 9, 10, 11  # battery state of charge 0..1, terminal volts, current drawn
DIST = 12  # distance driven by the axle centre, metres
GAIN_R, GAIN_L = 13, 14  # per-motor speed factors (seeded manufacturing spread)
LIGHT_R, LIGHT_L = 15, 16  # light received by the phototransistors, in threshold units
BUMP_FR, BUMP_FL, BUMP_REAR = 17, 18, 19  # bumper switches 0/1
CONTACT = 20  # 1 when the body touched something in the last tick (any side)
MASK = 21  # the input mask the engine will read, in its event layout
#: Declared sensors (robot file [sensors]) fill slots 0..MAX_SENSORS-1, one per input at most.
#: Their readings: metres for distance sensors, 1/0 for line sensors, light units for light sensors.
MAX_SENSORS = 8  # a fischertechnik controller has eight universal inputs I1..I8
READING = 22  # S[READING + k] is slot k's reading
N_STATE = READING + MAX_SENSORS

# --- parameters P[i, :] (one row per robot, so a batch may mix robots and battery levels) --------
P_DT = 0  # seconds per tick
P_BASE, P_WHEEL_R = 1, 2  # wheel base (track) and wheel radius, m
P_FRONT, P_REAR, P_HALF_W = 3, 4, 5  # body rectangle around the axle centre, m
P_OVERLAP, P_WRAP, P_GAP = 6, 7, 8  # bumper split overlap, wrap round the corners, switch travel, m
P_GYR2 = 9  # radius of gyration squared, m² (how contacts split into push and turn)
P_KV, P_VF, P_ALPHA, P_LEVELS = 10, 11, 12, 13  # m/s per volt, friction volts, lag factor, levels
P_VFULL, P_VEMPTY, P_RINT, P_CAP = 14, 15, 16, 17  # battery volts full/empty, ohms, ampere-seconds
P_IIDLE, P_IMOTOR = 18, 19  # amps of the electronics, amps per motor at full duty
P_PPR = 20  # encoder pulses per wheel turn
P_LX, P_LY, P_TOE = 21, 22, 23  # light sensor position (forward, ± sideways) and outward toe, rad
P_COS_FOV, P_EXP, P_DMIN = 24, 25, 26  # cosine of the field-of-view half angle, cos^k exponent, m
P_NMOTOR, P_NLIGHT = 27, 28  # per-tick noise: relative sd of motor speed and of light readings
P_DRANGE, P_DMIN_RANGE, P_DBEAM, P_DRES = 29, 30, 31, 32  # distance sensors: range, blind zone, m; half beam, rad;
#                                                          resolution, m
P_SENSOR = 33  # slot k's fields start at P_SENSOR + k * SENSOR_FIELDS
F_KIND, F_X, F_Y, F_AIM, F_ON, F_OFF, F_SIGN = 0, 1, 2, 3, 4, 5, 6  # kind (K_*), position (m, body frame), aim (rad),
#   the reading at which the event turns on and the one at which it turns off, +1 above / -1 below
SENSOR_FIELDS = 7
N_PARAM = P_SENSOR + MAX_SENSORS * SENSOR_FIELDS

# --- sensor kinds in F_KIND: tablebot.sensors.SensorKind.code (0 = no sensor in the slot) -------------

# --- noise Z[tick, i, :] ------------------------------------------------------------------------
Z_MOTOR_R, Z_MOTOR_L, Z_LIGHT_R, Z_LIGHT_L = 0, 1, 2, 3
N_NOISE = 4

# --- input bits B[:] in the engine's event layout (0 = not wired) -------------------------------
B_FR, B_FL, B_REAR, B_LIGHT_R, B_LIGHT_L = 0, 1, 2, 3, 4
B_SENSOR = 5  # B[B_SENSOR + k] is the event bit of sensor slot k (B may stop short: no more sensors)
N_BITS = B_SENSOR + MAX_SENSORS
