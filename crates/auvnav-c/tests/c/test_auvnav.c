/* The C interface's test program (scripts/c-test.sh): host gcc and
   arm-none-eabi-gcc under QEMU mps2-an386. No malloc, static storage only;
   it includes auvnav.h and its generated data (lines.h), and gets two
   output functions from the platform file (io_host.c or io_semihost.c).

   1. Every shared profile planned with auvnav_plan_next, track by track:
      the same depths, statuses, minimum altitudes (and certified minimum
      altitudes, safety, optimizer stops) as `plan --json --horizon 5`,
      compared bit for bit with the tool's printed values; a track whose
      predicted start is below the bottom climbed with auvnav_planner_carry,
      as the tool climbs it.
   2. Every function, every error code of capi.md: null pointers, NaN,
      over-capacity lengths, invalid settings, uninitialized objects. */
#include "auvnav.h"

/* The platform's output (io_*.c): a string, and the exit status. */
void test_write(const char *s);
void test_exit(int status);
/* Stack high-water mark of the last measured call, bytes (0: not measured). */
void test_stack_begin(void);
uint32_t test_stack_end(void);

struct want {
  float depth, min_altitude, certified;
  uint32_t status, optimizer;
  bool safe, after_crash;
};
struct line {
  const char *name;
  float h_r, h_a;
  uint32_t n_samples;
  const float *x, *b;
  uint32_t n_waypoints;
  const float *w;
  uint32_t n_tracks;
  const struct want *want;
};
#include "lines.h"

/* C99 static checks of the opaque objects (the header checks the sizes). */
typedef char check_planner_align[(offsetof(struct { char c; auvnav_planner p; }, p) == AUVNAV_OBJECT_ALIGN) ? 1 : -1];
typedef char check_autopilot_align[(offsetof(struct { char c; auvnav_autopilot a; }, a) == AUVNAV_OBJECT_ALIGN) ? 1 : -1];

static auvnav_planner planner;       /* statically placed */
static auvnav_planner never_inited;  /* zeroed, never passed to init */
static auvnav_autopilot autopilot;
static auvnav_autopilot ap_never_inited;
static float big[AUVNAV_MAX_SAMPLES + 1];
static float big_b[AUVNAV_MAX_SAMPLES + 1];

/* NaN and infinity without <math.h>. */
static float not_a_number(void) { volatile float z = 0.0f; return z / z; }
static float infinity(void) { volatile float z = 0.0f; return 1.0f / z; }

static int failures;
static int checks;
static uint32_t stack_max[8];
enum { S_INIT, S_SET_LINE, S_PLAN_NEXT, S_CARRY, S_MEASURED, S_AP_INIT, S_AP_STEP, S_N };
static const char *const STACK_NAME[S_N] = {
  "auvnav_planner_init", "auvnav_planner_set_line", "auvnav_plan_next",
  "auvnav_planner_carry", "auvnav_planner_measured", "auvnav_autopilot_init",
  "auvnav_autopilot_step"};

static void put_u(uint32_t v) {
  char buf[11];
  int i = 10;
  buf[i] = 0;
  do { buf[--i] = (char)('0' + v % 10u); v /= 10u; } while (v && i > 0);
  test_write(buf + i);
}
static void put_i(int32_t v) {
  if (v < 0) { test_write("-"); put_u((uint32_t)(-(v + 1)) + 1u); } else put_u((uint32_t)v);
}
static uint32_t bits(float f) {
  union { float f; uint32_t u; } c;
  c.f = f;
  return c.u;
}
static void put_hex(uint32_t v) {
  char buf[11] = "0x00000000";
  int i;
  for (i = 0; i < 8; i++) buf[9 - i] = "0123456789abcdef"[(v >> (4 * i)) & 15u];
  test_write(buf);
}
/* A float to 4 decimals, for reading (the comparison is on the bits). */
static void put_f(float f) {
  uint32_t whole, frac;
  if (f != f) { test_write("nan"); return; }
  if (f < 0) { test_write("-"); f = -f; }
  if (f > 4e9f) { test_write("big"); return; }
  whole = (uint32_t)f;
  frac = (uint32_t)((f - (float)whole) * 10000.0f + 0.5f);
  if (frac >= 10000u) { whole++; frac -= 10000u; }
  put_u(whole);
  test_write(".");
  if (frac < 1000u) test_write("0");
  if (frac < 100u) test_write("0");
  if (frac < 10u) test_write("0");
  put_u(frac);
}
static int str_eq(const char *a, const char *b) {
  while (*a && *a == *b) { a++; b++; }
  return *a == *b;
}

static void check(int ok, const char *what) {
  checks++;
  if (!ok) {
    failures++;
    test_write("FAIL: ");
    test_write(what);
    test_write("\n");
  }
}
static void expect_code(int32_t got, int32_t want, const char *what) {
  checks++;
  if (got != want) {
    failures++;
    test_write("FAIL: ");
    test_write(what);
    test_write(": got ");
    test_write(auvnav_error_name(got));
    test_write(", want ");
    test_write(auvnav_error_name(want));
    test_write("\n");
  }
}
static void stack_note(int which) {
  uint32_t used = test_stack_end();
  if (used > stack_max[which]) stack_max[which] = used;
}

static void mission_for(auvnav_mission *m, const struct line *l) {
  auvnav_mission_default(m);
  m->reference_altitude = l->h_r;
  m->min_altitude = l->h_a;
}

/* 1. A line planned track by track against the tool's report. */
static void plan_line(const struct line *l) {
  auvnav_vehicle v;
  auvnav_mission m;
  auvnav_settings s;
  auvnav_plan p;
  uint32_t t;
  int32_t rc;
  int same = 1;
  auvnav_vehicle_default(&v);
  mission_for(&m, l);
  auvnav_settings_default(&s);
  s.horizon = 5;
  test_stack_begin();
  rc = auvnav_planner_init(&planner, &v, &m, &s);
  stack_note(S_INIT);
  expect_code(rc, AUVNAV_OK, "planner_init");
  test_stack_begin();
  rc = auvnav_planner_set_line(&planner, l->x, l->b, l->n_samples, l->w, l->n_waypoints, not_a_number());
  stack_note(S_SET_LINE);
  expect_code(rc, AUVNAV_OK, "planner_set_line");
  test_write(l->name);
  test_write("\n");
  for (t = 0; t < l->n_tracks; t++) {
    const struct want *w = &l->want[t];
    check(auvnav_planner_track(&planner) == t + 1, "planner_track counts tracks");
    test_stack_begin();
    rc = auvnav_plan_next(&planner, &p);
    stack_note(S_PLAN_NEXT);
    test_write("  track ");
    put_u(t + 1);
    if (w->after_crash) {
      /* The tool flies a track whose predicted start is below the bottom
         at the shallowest depth, unplanned, its worlds carried through
         the climb, and plans on from where the climb ends: so does the
         C caller. */
      test_write(": after the predicted collision: ");
      test_write(auvnav_error_name(rc));
      test_write(", climbed\n");
      expect_code(rc, AUVNAV_ERR_BELOW_BOTTOM, "plan_next after a collision");
      check(auvnav_planner_track(&planner) == t + 1, "no advance on an error");
      test_stack_begin();
      rc = auvnav_planner_carry(&planner, m.depth_min);
      stack_note(S_CARRY);
      expect_code(rc, AUVNAV_OK, "planner_carry (the climb)");
      check(auvnav_planner_track(&planner) == t + 2, "carry advances");
      continue;
    }
    expect_code(rc, AUVNAV_OK, "plan_next");
    test_write(": depth ");
    put_f(p.depth);
    test_write(" (");
    put_hex(bits(p.depth));
    test_write(") min altitude ");
    put_f(p.min_altitude);
    test_write(" (");
    put_hex(bits(p.min_altitude));
    test_write(") status ");
    put_u(p.status);
    if (bits(p.depth) != bits(w->depth) || bits(p.min_altitude) != bits(w->min_altitude) ||
        bits(p.certified_min_altitude) != bits(w->certified) || p.status != w->status ||
        p.optimizer != w->optimizer || p.safe != w->safe) {
      same = 0;
      test_write("  DIFFERS from plan --json: depth ");
      put_hex(bits(w->depth));
      test_write(" min altitude ");
      put_hex(bits(w->min_altitude));
      test_write(" status ");
      put_u(w->status);
    }
    test_write("\n");
  }
  if (t == l->n_tracks) {
    expect_code(auvnav_plan_next(&planner, &p), AUVNAV_ERR_LINE_DONE, "plan_next after the last track");
    expect_code(auvnav_planner_carry(&planner, 10.0f), AUVNAV_ERR_LINE_DONE, "carry after the last track");
  }
  check(same, "the depths, statuses and minimum altitudes equal plan --json's");
}

/* 2a. The defaults and the error names. */
static void defaults_and_names(void) {
  auvnav_vehicle v;
  auvnav_mission m;
  auvnav_settings s;
  int32_t c;
  auvnav_vehicle_default(&v);
  check(v.speed == 1.5f && v.sample_time == 0.1f && v.pitch_limit == 25.0f && v.elevator_limit == 25.0f,
        "vehicle_default: speed, sample time, limits (model.md section 9)");
  check(v.depth_kp == 1.5f && v.depth_ki == 0.0f && v.depth_kd == 2.0f && v.pitch_kp == 2.0f &&
        v.pitch_ki == 0.1f && v.pitch_kd == 3.0f, "vehicle_default: gains");
  check(v.plant_kind == AUVNAV_PLANT_PITCH && v.num_len == 1 && v.den_len == 4 && v.num[0] == -0.173f &&
        v.den[0] == 1.0f && v.den[1] == 2.681f && v.den[2] == 0.546f && v.den[3] == 0.048f,
        "vehicle_default: C-AUV #4 plant");
  auvnav_mission_default(&m);
  check(m.reference_altitude == 80.0f && m.min_altitude == 60.0f && m.depth_min == 0.0f &&
        m.depth_max == 6000.0f && m.horizontal_uncertainty == 0.0f && m.nav_drift == 0.0f &&
        m.vertical_uncertainty == 0.0f && m.speed_uncertainty == 0.0f && m.flight_path_offset == 0.0f &&
        m.vertical_current == 0.0f, "mission_default");
  auvnav_settings_default(&s);
  check(s.mode == AUVNAV_MODE_HORIZON && s.method == AUVNAV_METHOD_BFGS && s.horizon == AUVNAV_MAX_HORIZON &&
        s.max_iterations == 200 && s.max_flights == 0, "settings_default");
  auvnav_vehicle_default(NULL);
  auvnav_mission_default(NULL);
  auvnav_settings_default(NULL);
  check(str_eq(auvnav_error_name(AUVNAV_OK), "AUVNAV_OK"), "error_name(OK)");
  check(str_eq(auvnav_error_name(AUVNAV_ERR_NULL), "AUVNAV_ERR_NULL"), "error_name(NULL)");
  check(str_eq(auvnav_error_name(AUVNAV_ERR_SIMULATION), "AUVNAV_ERR_SIMULATION"), "error_name(SIMULATION)");
  check(str_eq(auvnav_error_name(7), "AUVNAV_ERR_UNKNOWN"), "error_name(unknown)");
  for (c = AUVNAV_OK; c >= AUVNAV_ERR_SIMULATION; c--)
    check(!str_eq(auvnav_error_name(c), "AUVNAV_ERR_UNKNOWN"), "every code has a name");
}

/* 2b. planner_init: nulls, NaN, invalid vehicle, plant, mission, settings. */
static void init_errors(void) {
  auvnav_vehicle v, dv;
  auvnav_mission m, dm;
  auvnav_settings s, ds;
  auvnav_vehicle_default(&dv);
  auvnav_mission_default(&dm);
  auvnav_settings_default(&ds);
  v = dv; m = dm; s = ds;
  expect_code(auvnav_planner_init(NULL, &v, &m, &s), AUVNAV_ERR_NULL, "init(NULL planner)");
  expect_code(auvnav_planner_init(&planner, NULL, &m, &s), AUVNAV_ERR_NULL, "init(NULL vehicle)");
  expect_code(auvnav_planner_init(&planner, &v, NULL, &s), AUVNAV_ERR_NULL, "init(NULL mission)");
  expect_code(auvnav_planner_init(&planner, &v, &m, NULL), AUVNAV_ERR_NULL, "init(NULL settings)");
  expect_code(auvnav_planner_track(&planner), 0, "a failed init leaves the planner uninitialized");
  v.speed = not_a_number();
  expect_code(auvnav_planner_init(&planner, &v, &m, &s), AUVNAV_ERR_NON_FINITE, "init(speed NaN)");
  v = dv; v.den[2] = infinity();
  expect_code(auvnav_planner_init(&planner, &v, &m, &s), AUVNAV_ERR_NON_FINITE, "init(den infinite)");
  v = dv; v.pitch_kd = -1.0f;
  expect_code(auvnav_planner_init(&planner, &v, &m, &s), AUVNAV_ERR_VEHICLE, "init(negative gain)");
  v = dv; v.pitch_limit = 95.0f;
  expect_code(auvnav_planner_init(&planner, &v, &m, &s), AUVNAV_ERR_VEHICLE, "init(pitch_limit 95)");
  v = dv; v.sample_time = 0.0f;
  expect_code(auvnav_planner_init(&planner, &v, &m, &s), AUVNAV_ERR_VEHICLE, "init(sample_time 0)");
  v = dv; v.plant_kind = 7;
  expect_code(auvnav_planner_init(&planner, &v, &m, &s), AUVNAV_ERR_PLANT, "init(plant_kind 7)");
  v = dv; v.den_len = AUVNAV_MAX_ORDER + 2;
  expect_code(auvnav_planner_init(&planner, &v, &m, &s), AUVNAV_ERR_CAPACITY, "init(den_len over capacity)");
  v = dv; v.num_len = 3;
  expect_code(auvnav_planner_init(&planner, &v, &m, &s), AUVNAV_ERR_PLANT, "init(relative degree 1)");
  v = dv; v.den_len = 0;
  expect_code(auvnav_planner_init(&planner, &v, &m, &s), AUVNAV_ERR_PLANT, "init(no denominator)");
  v = dv; v.plant_kind = AUVNAV_PLANT_RATE;
  expect_code(auvnav_planner_init(&planner, &v, &m, &s), AUVNAV_ERR_PLANT, "init(rate plant, constant term not 0)");
  v = dv;
  m.min_altitude = 90.0f;
  expect_code(auvnav_planner_init(&planner, &v, &m, &s), AUVNAV_ERR_MISSION, "init(h_a above h_r)");
  m = dm; m.reference_altitude = not_a_number();
  expect_code(auvnav_planner_init(&planner, &v, &m, &s), AUVNAV_ERR_NON_FINITE, "init(h_r NaN)");
  m = dm; m.depth_min = 100.0f; m.depth_max = 10.0f;
  expect_code(auvnav_planner_init(&planner, &v, &m, &s), AUVNAV_ERR_MISSION, "init(depth limits reversed)");
  m = dm; m.nav_drift = 1.5f;
  expect_code(auvnav_planner_init(&planner, &v, &m, &s), AUVNAV_ERR_MISSION, "init(nav_drift 1.5)");
  m = dm; m.flight_path_offset = 30.0f;
  expect_code(auvnav_planner_init(&planner, &v, &m, &s), AUVNAV_ERR_MISSION, "init(flight path offset above pitch limit)");
  m = dm; m.vertical_uncertainty = -1.0f;
  expect_code(auvnav_planner_init(&planner, &v, &m, &s), AUVNAV_ERR_MISSION, "init(negative uncertainty)");
  m = dm;
  s.mode = 9;
  expect_code(auvnav_planner_init(&planner, &v, &m, &s), AUVNAV_ERR_SETTINGS, "init(mode 9)");
  s = ds; s.method = 9;
  expect_code(auvnav_planner_init(&planner, &v, &m, &s), AUVNAV_ERR_SETTINGS, "init(method 9)");
  s = ds; s.horizon = 0;
  expect_code(auvnav_planner_init(&planner, &v, &m, &s), AUVNAV_ERR_SETTINGS, "init(horizon 0)");
  s = ds; s.horizon = AUVNAV_MAX_HORIZON + 1;
  expect_code(auvnav_planner_init(&planner, &v, &m, &s), AUVNAV_ERR_SETTINGS, "init(horizon over capacity)");
  s = ds; s.max_iterations = 0;
  expect_code(auvnav_planner_init(&planner, &v, &m, &s), AUVNAV_ERR_SETTINGS, "init(max_iterations 0)");
  s = ds;
  expect_code(auvnav_plan_next(&planner, NULL), AUVNAV_ERR_NOT_INITIALIZED, "plan_next after a failed init");
  /* Never initialized (zeroed static storage). */
  {
    auvnav_plan p;
    auvnav_measurement me = {100.0f, 0.0f, 0.0f, 0.0f};
    const float x[2] = {0.0f, 100.0f};
    expect_code(auvnav_plan_next(&never_inited, &p), AUVNAV_ERR_NOT_INITIALIZED, "plan_next(never initialized)");
    expect_code(auvnav_planner_set_line(&never_inited, x, x, 2, x, 2, 0.0f), AUVNAV_ERR_NOT_INITIALIZED,
                "set_line(never initialized)");
    expect_code(auvnav_planner_measured(&never_inited, &me), AUVNAV_ERR_NOT_INITIALIZED, "measured(never initialized)");
    expect_code(auvnav_planner_carry(&never_inited, 10.0f), AUVNAV_ERR_NOT_INITIALIZED, "carry(never initialized)");
    expect_code(auvnav_planner_carry(NULL, 10.0f), AUVNAV_ERR_NULL, "carry(NULL)");
    check(auvnav_planner_track(&never_inited) == 0 && auvnav_planner_track(NULL) == 0, "track(uninitialized, NULL) is 0");
    expect_code(auvnav_plan_next(NULL, &p), AUVNAV_ERR_NULL, "plan_next(NULL)");
    expect_code(auvnav_planner_measured(NULL, &me), AUVNAV_ERR_NULL, "measured(NULL)");
    expect_code(auvnav_planner_set_line(NULL, x, x, 2, x, 2, 0.0f), AUVNAV_ERR_NULL, "set_line(NULL)");
  }
}

static const struct line *find_line(const char *name) {
  int i;
  for (i = 0; i < N_LINES; i++)
    if (str_eq(LINES[i].name, name)) return &LINES[i];
  return &LINES[0];
}

/* 2c. set_line, plan_next, measured: every error of the line's calls. */
static void line_errors(void) {
  const struct line *l = find_line("us_monterey_canyon_1");
  const struct line *shallow = find_line("jp_aburatsubo_sagami_1");
  auvnav_vehicle v;
  auvnav_mission m;
  auvnav_settings s;
  auvnav_plan p;
  auvnav_measurement me;
  uint32_t i, n = l->n_samples;
  const float back[3] = {0.0f, 2000.0f, 1000.0f};
  const float outside[2] = {0.0f, 9000.0f};
  auvnav_vehicle_default(&v);
  mission_for(&m, l);
  auvnav_settings_default(&s);
  expect_code(auvnav_planner_init(&planner, &v, &m, &s), AUVNAV_OK, "init");
  expect_code(auvnav_plan_next(&planner, &p), AUVNAV_ERR_NO_LINE, "plan_next before set_line");
  me.depth = 900.0f; me.pitch = 0.0f; me.pitch_rate = 0.0f; me.x = 0.0f;
  expect_code(auvnav_planner_measured(&planner, &me), AUVNAV_ERR_NO_LINE, "measured before set_line");
  expect_code(auvnav_planner_carry(&planner, 10.0f), AUVNAV_ERR_NO_LINE, "carry before set_line");
  for (i = 0; i < n; i++) { big[i] = l->x[i]; big_b[i] = l->b[i]; }
#define SET(x_, b_, ns_, w_, nw_, d_) auvnav_planner_set_line(&planner, x_, b_, ns_, w_, nw_, d_)
  expect_code(SET(NULL, l->b, n, l->w, l->n_waypoints, 0.0f), AUVNAV_ERR_NULL, "set_line(NULL x)");
  expect_code(SET(l->x, NULL, n, l->w, l->n_waypoints, 0.0f), AUVNAV_ERR_NULL, "set_line(NULL bottom)");
  expect_code(SET(l->x, l->b, n, NULL, l->n_waypoints, 0.0f), AUVNAV_ERR_NULL, "set_line(NULL waypoints)");
  expect_code(SET(big, big_b, AUVNAV_MAX_SAMPLES + 1, l->w, l->n_waypoints, 0.0f), AUVNAV_ERR_CAPACITY,
              "set_line(samples over capacity)");
  expect_code(SET(l->x, l->b, n, big, AUVNAV_MAX_WAYPOINTS + 1, 0.0f), AUVNAV_ERR_CAPACITY,
              "set_line(waypoints over capacity)");
  expect_code(SET(l->x, l->b, 1, l->w, l->n_waypoints, 0.0f), AUVNAV_ERR_PROFILE, "set_line(one sample)");
  big[5] = big[4];
  expect_code(SET(big, big_b, n, l->w, l->n_waypoints, 0.0f), AUVNAV_ERR_PROFILE, "set_line(x not increasing)");
  big[5] = l->x[5];
  big_b[7] = not_a_number();
  expect_code(SET(big, big_b, n, l->w, l->n_waypoints, 0.0f), AUVNAV_ERR_NON_FINITE, "set_line(bottom NaN)");
  big_b[7] = l->b[7];
  expect_code(SET(l->x, l->b, n, l->w, 1, 0.0f), AUVNAV_ERR_WAYPOINTS, "set_line(one waypoint)");
  expect_code(SET(l->x, l->b, n, back, 3, 0.0f), AUVNAV_ERR_WAYPOINTS, "set_line(waypoints not increasing)");
  expect_code(SET(l->x, l->b, n, outside, 2, 0.0f), AUVNAV_ERR_WAYPOINTS, "set_line(waypoint outside the bottom)");
  expect_code(SET(l->x, l->b, n, l->w, l->n_waypoints, -5.0f), AUVNAV_ERR_START, "set_line(start above the surface)");
  expect_code(SET(l->x, l->b, n, l->w, l->n_waypoints, 5000.0f), AUVNAV_ERR_START, "set_line(start below the bottom)");
  expect_code(SET(l->x, l->b, n, l->w, l->n_waypoints, infinity()), AUVNAV_ERR_NON_FINITE, "set_line(start infinite)");
  expect_code(SET(shallow->x, shallow->b, shallow->n_samples, shallow->w, shallow->n_waypoints, not_a_number()),
              AUVNAV_ERR_START, "set_line(h_r deeper than the water at waypoint 0)");
  expect_code(auvnav_plan_next(&planner, &p), AUVNAV_ERR_NO_LINE, "plan_next after a failed set_line");
  /* A good line, then the measured state. */
  expect_code(SET(l->x, l->b, n, l->w, l->n_waypoints, not_a_number()), AUVNAV_OK, "set_line");
#undef SET
  expect_code(auvnav_plan_next(&planner, NULL), AUVNAV_ERR_NULL, "plan_next(NULL out)");
  expect_code(auvnav_planner_carry(&planner, not_a_number()), AUVNAV_ERR_NON_FINITE, "carry(depth NaN)");
  check(auvnav_planner_track(&planner) == 1, "no advance on a carry's error");
  expect_code(auvnav_planner_measured(&planner, NULL), AUVNAV_ERR_NULL, "measured(NULL)");
  me.depth = not_a_number();
  expect_code(auvnav_planner_measured(&planner, &me), AUVNAV_ERR_NON_FINITE, "measured(depth NaN)");
  me.depth = 990.0f; me.pitch_rate = infinity();
  expect_code(auvnav_planner_measured(&planner, &me), AUVNAV_ERR_NON_FINITE, "measured(pitch rate infinite)");
  /* Measured 4 m deeper than the start, nose up 1 deg: still plannable. */
  me.depth = l->b[0] - l->h_r + 4.0f; me.pitch = 1.0f; me.pitch_rate = 0.0f; me.x = 0.0f;
  test_stack_begin();
  expect_code(auvnav_planner_measured(&planner, &me), AUVNAV_OK, "measured");
  stack_note(S_MEASURED);
  expect_code(auvnav_plan_next(&planner, &p), AUVNAV_OK, "plan_next from a measured state");
  check(p.depth == p.depth && p.depth >= 0.0f && p.depth <= 6000.0f && auvnav_planner_track(&planner) == 2,
        "a measured start gives a plan within the limits");
  /* A measured position far off the next track. */
  me.x = -5000.0f;
  expect_code(auvnav_planner_measured(&planner, &me), AUVNAV_OK, "measured(off the track)");
  expect_code(auvnav_plan_next(&planner, &p), AUVNAV_ERR_OFF_TRACK, "plan_next from a state off the track");
  /* Below the bottom. */
  me.x = l->w[1]; me.depth = 5000.0f;
  expect_code(auvnav_planner_measured(&planner, &me), AUVNAV_OK, "measured(below the bottom)");
  expect_code(auvnav_plan_next(&planner, &p), AUVNAV_ERR_BELOW_BOTTOM, "plan_next from below the bottom");
}

/* 2d. The autopilot: every function and its codes, hold, NaN, bumpless. */
static void autopilot_checks(void) {
  auvnav_vehicle v;
  float e = 123.0f, e1, e2, held;
  int k;
  auvnav_vehicle_default(&v);
  expect_code(auvnav_autopilot_init(NULL, &v), AUVNAV_ERR_NULL, "autopilot_init(NULL)");
  expect_code(auvnav_autopilot_init(&autopilot, NULL), AUVNAV_ERR_NULL, "autopilot_init(NULL vehicle)");
  expect_code(auvnav_autopilot_step(&ap_never_inited, 10.0f, 10.0f, 0.0f, 0.0f, &e), AUVNAV_ERR_NOT_INITIALIZED,
              "autopilot_step(never initialized)");
  expect_code(auvnav_autopilot_hold(&ap_never_inited, true), AUVNAV_ERR_NOT_INITIALIZED, "autopilot_hold(never initialized)");
  expect_code(auvnav_autopilot_engage(&ap_never_inited, 0.0f), AUVNAV_ERR_NOT_INITIALIZED, "autopilot_engage(never initialized)");
  expect_code(auvnav_autopilot_step(NULL, 10.0f, 10.0f, 0.0f, 0.0f, &e), AUVNAV_ERR_NULL, "autopilot_step(NULL)");
  v.elevator_limit = -1.0f;
  expect_code(auvnav_autopilot_init(&autopilot, &v), AUVNAV_ERR_VEHICLE, "autopilot_init(negative limit)");
  v.elevator_limit = not_a_number();
  expect_code(auvnav_autopilot_init(&autopilot, &v), AUVNAV_ERR_NON_FINITE, "autopilot_init(limit NaN)");
  auvnav_vehicle_default(&v);
  v.den_len = 9;
  expect_code(auvnav_autopilot_init(&autopilot, &v), AUVNAV_ERR_CAPACITY, "autopilot_init(den_len over capacity)");
  auvnav_vehicle_default(&v);
  test_stack_begin();
  expect_code(auvnav_autopilot_init(&autopilot, &v), AUVNAV_OK, "autopilot_init");
  stack_note(S_AP_INIT);
  expect_code(auvnav_autopilot_step(&autopilot, 50.0f, 50.0f, 0.0f, 0.0f, NULL), AUVNAV_ERR_NULL, "autopilot_step(NULL out)");
  test_stack_begin();
  expect_code(auvnav_autopilot_step(&autopilot, 50.0f, 50.0f, 0.0f, 0.0f, &e), AUVNAV_OK, "autopilot_step");
  stack_note(S_AP_STEP);
  check(e == 0.0f, "level and on depth: no elevator");
  /* 2 m too shallow: nose down, elevator +6 deg (the Rust unit test's case). */
  expect_code(auvnav_autopilot_step(&autopilot, 52.0f, 50.0f, 0.0f, 0.0f, &e), AUVNAV_OK, "autopilot_step");
  check(e > 5.9f && e < 6.1f, "2 m too shallow: elevator 6 deg");
  held = e;
  expect_code(auvnav_autopilot_step(&autopilot, 52.0f, not_a_number(), 0.0f, 0.0f, &e1), AUVNAV_ERR_NON_FINITE,
              "autopilot_step(depth NaN)");
  check(e1 == held, "NaN depth: the last command held");
  expect_code(auvnav_autopilot_step(&autopilot, 52.0f, 50.0f, 0.0f, infinity(), &e1), AUVNAV_ERR_NON_FINITE,
              "autopilot_step(pitch rate infinite)");
  check(e1 == held, "infinite pitch rate: the last command held");
  expect_code(auvnav_autopilot_step(&autopilot, 52.0f, 50.0f, 0.0f, 0.0f, &e2), AUVNAV_OK, "autopilot_step after NaN");
  check(e2 - held < 0.05f && held - e2 < 0.05f, "after NaN: bumpless (continues from the held command)");
  expect_code(auvnav_autopilot_hold(NULL, true), AUVNAV_ERR_NULL, "autopilot_hold(NULL)");
  expect_code(auvnav_autopilot_hold(&autopilot, true), AUVNAV_OK, "autopilot_hold");
  held = e2;
  for (k = 0; k < 20; k++) {
    expect_code(auvnav_autopilot_step(&autopilot, 80.0f, 50.0f + 0.1f * (float)k, 0.0f, 0.0f, &e), AUVNAV_OK, "step on hold");
    check(e == held, "on hold: the command held");
  }
  expect_code(auvnav_autopilot_hold(&autopilot, false), AUVNAV_OK, "autopilot_hold(release)");
  expect_code(auvnav_autopilot_step(&autopilot, 80.0f, 52.0f, 0.0f, 0.0f, &e), AUVNAV_OK, "step after hold");
  check(e - held < 0.05f && held - e < 0.05f, "released: bumpless (continues from the held command)");
  expect_code(auvnav_autopilot_engage(NULL, 1.0f), AUVNAV_ERR_NULL, "autopilot_engage(NULL)");
  expect_code(auvnav_autopilot_engage(&autopilot, not_a_number()), AUVNAV_ERR_NON_FINITE, "autopilot_engage(NaN)");
  expect_code(auvnav_autopilot_engage(&autopilot, -7.0f), AUVNAV_OK, "autopilot_engage");
  expect_code(auvnav_autopilot_step(&autopilot, 50.0f, 50.0f, 0.0f, 0.0f, &e), AUVNAV_OK, "step after engage");
  check(e > -7.05f && e < -6.95f, "engaged at -7 deg: the first command continues from it");
}

int main(void) {
  int i;
  test_write("auvnav C interface test\n");
  defaults_and_names();
  init_errors();
  line_errors();
  autopilot_checks();
  for (i = 0; i < N_LINES; i++) plan_line(&LINES[i]);
  for (i = 0; i < S_N; i++) {
    test_write("stack ");
    test_write(STACK_NAME[i]);
    test_write(": ");
    if (stack_max[i]) { put_u(stack_max[i]); test_write(" B\n"); } else test_write("not measured on this platform\n");
  }
  put_i(failures);
  test_write(" failures in ");
  put_i(checks);
  test_write(" checks\n");
  test_exit(failures ? 1 : 0);
  return failures ? 1 : 0;
}
