//! The motion model of an emulated pan-tilt head, shared by every head
//! emulator. Positions are integer counts of the protocol's own unit
//! (µrad for campanile-link, 1/100° for Pelco-D, PTU positions for FLIR).
//!
//! By default each axis slews at constant speed towards its target and
//! stops exactly on it (the historic model; acceleration is stored by the
//! protocols but not simulated). [`Dynamics`] switches on, per axis:
//!
//! - **acceleration**: a trapezoidal velocity profile (accelerate at `accel`
//!   up to `speed`, cruise, decelerate at `accel` onto the target; a
//!   triangle when the move is too short to reach `speed`). A target or
//!   speed change mid-move replans from the current position and velocity,
//!   braking first if the axis would otherwise overshoot;
//! - **settle time**: after arriving the axis stays "moving" for
//!   `settle_ms` before it reports idle;
//! - **backlash**: the output shaft follows the motor through a dead band of
//!   width `backlash` counts. The gear is preloaded so that the output sits
//!   exactly on the motor after a move in the negative direction and lags it
//!   by the full width after a move in the positive direction; after a
//!   reversal the motor turns through the dead band before the output moves.
//!   [`Axis::true_position`] is the output (ground truth); the encoder is on
//!   the motor and does not see the backlash;
//! - **encoder noise**: reported positions ([`Head::read_pan`],
//!   [`Head::read_tilt`]) are the motor position plus seeded Gaussian noise
//!   of standard deviation `encoder_sigma` counts, rounded to whole counts.
//!
//! Everything is deterministic: time is the integer milliseconds the
//! firmware is advanced by, and the encoder noise comes from a SplitMix64
//! stream seeded by [`Head::seed_encoder`]. The model is `no_std` (no
//! allocator, no `libm`: the few roots and roundings it needs are written
//! out here).
//!
//! Stops ([`Axis::stop`]) are immediate, whatever the acceleration (an
//! emergency halt), and homing ([`Head::home`] in the protocols) is a move
//! to the home pose: the position is always known.

/// Optional dynamics of one axis. The default (all zero) is the historic
/// constant-speed model.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Dynamics {
    /// Acceleration and deceleration, counts/s²; 0 means speed changes
    /// instantly.
    pub accel: u32,
    /// Time an axis keeps reporting "moving" after it arrives, ms.
    pub settle_ms: u32,
    /// Backlash (dead band) width, counts; 0 for none.
    pub backlash: f64,
    /// Standard deviation of the encoder noise on reported positions,
    /// counts; 0 for none.
    pub encoder_sigma: f64,
}

/// One phase of constant acceleration.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Segment {
    /// Length, seconds.
    duration: f64,
    /// Acceleration, counts/s².
    accel: f64,
}

/// A planned move: from `p0` at velocity `v0` to `target`, through up to
/// four constant-acceleration segments.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Plan {
    p0: f64,
    v0: f64,
    target: i32,
    speed: u32,
    accel: u32,
    segments: [Segment; 4],
    count: usize,
    duration: f64,
    /// Whether the plan moves the axis at all (a plan that does not move it
    /// does not settle).
    moves: bool,
}

impl Plan {
    const fn at_rest(position: i32, speed: u32, accel: u32) -> Self {
        Self {
            p0: position as f64,
            v0: 0.0,
            target: position,
            speed,
            accel,
            segments: [Segment {
                duration: 0.0,
                accel: 0.0,
            }; 4],
            count: 0,
            duration: 0.0,
            moves: false,
        }
    }

    fn new(p0: f64, v0: f64, target: i32, speed: u32, accel: u32) -> Self {
        let mut plan = Self::at_rest(target, speed, accel);
        plan.p0 = p0;
        let goal = f64::from(target);
        plan.moves = p0 != goal || v0 != 0.0;
        if speed == 0 || !plan.moves {
            return plan;
        }
        let vmax = f64::from(speed);
        if accel == 0 {
            // Constant speed: velocity changes instantly.
            let d = goal - p0;
            plan.v0 = if d < 0.0 { -vmax } else { vmax };
            plan.push(abs(d) / vmax, 0.0);
            return plan;
        }
        let a = f64::from(accel);
        plan.v0 = v0;
        let (mut p, mut v) = (p0, v0);
        // Brake to rest first if moving away from the target or too fast to
        // stop on it.
        let d = goal - p;
        if v != 0.0 && (sign(v) != sign(d) || v * v / (2.0 * a) > abs(d)) {
            let t = abs(v) / a;
            p += v * t / 2.0;
            plan.push(t, -sign(v) * a);
            v = 0.0;
        }
        let d = goal - p;
        let s = sign(d);
        let (u, dist) = (abs(v), abs(d));
        if dist == 0.0 {
            return plan;
        }
        if u > vmax {
            // Slow to the (new, lower) top speed, cruise, brake.
            let t1 = (u - vmax) / a;
            let d1 = (u * u - vmax * vmax) / (2.0 * a);
            let d3 = vmax * vmax / (2.0 * a);
            plan.push(t1, -s * a);
            plan.push(max0(dist - d1 - d3) / vmax, 0.0);
            plan.push(vmax / a, -s * a);
        } else {
            // Trapezoid, or a triangle if the top speed is out of reach.
            let peak = min(vmax, sqrt(a * dist + u * u / 2.0));
            let d1 = (peak * peak - u * u) / (2.0 * a);
            let d3 = peak * peak / (2.0 * a);
            plan.push((peak - u) / a, s * a);
            plan.push(max0(dist - d1 - d3) / peak, 0.0);
            plan.push(peak / a, -s * a);
        }
        plan
    }

    fn push(&mut self, duration: f64, accel: f64) {
        if duration > 0.0 && self.count < self.segments.len() {
            self.segments[self.count] = Segment { duration, accel };
            self.count += 1;
            self.duration += duration;
        }
    }

    /// Position and velocity `t` seconds after the plan started.
    fn at(&self, t: f64) -> (f64, f64) {
        if t >= self.duration {
            return (f64::from(self.target), 0.0);
        }
        let (mut p, mut v, mut left) = (self.p0, self.v0, t);
        for seg in &self.segments[..self.count] {
            let dt = min(left, seg.duration);
            p += v * dt + 0.5 * seg.accel * dt * dt;
            v += seg.accel * dt;
            left -= dt;
            if left <= 0.0 {
                break;
            }
        }
        (p, v)
    }
}

/// One axis: position, target, soft limits, slew speed and dynamics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Axis {
    /// Current motor position, whole counts (truncated towards the target
    /// while moving, so it equals the target only on arrival).
    pub position: i32,
    /// Commanded position, counts.
    pub target: i32,
    /// Lowest allowed position, counts.
    pub min: i32,
    /// Highest allowed position, counts.
    pub max: i32,
    /// Slew speed, counts per second (0 means "instantaneous").
    pub speed: u32,
    /// Acceleration, settle time, backlash and encoder noise.
    pub dynamics: Dynamics,
    /// Exact motor position, counts.
    motor: f64,
    /// Motor velocity, counts/s.
    velocity: f64,
    /// Output shaft position (after backlash), counts.
    output: f64,
    plan: Plan,
    /// Milliseconds since the plan started.
    elapsed_ms: u64,
}

impl Axis {
    /// An axis at `home`, with limits and speed, and no extra dynamics.
    pub const fn new(home: i32, min: i32, max: i32, speed: u32) -> Self {
        Self {
            position: home,
            target: home,
            min,
            max,
            speed,
            dynamics: Dynamics {
                accel: 0,
                settle_ms: 0,
                backlash: 0.0,
                encoder_sigma: 0.0,
            },
            motor: home as f64,
            velocity: 0.0,
            output: home as f64,
            plan: Plan::at_rest(home, speed, 0),
            elapsed_ms: 0,
        }
    }

    /// The same axis with `dynamics`.
    pub const fn with_dynamics(mut self, dynamics: Dynamics) -> Self {
        self.dynamics = dynamics;
        self
    }

    /// Whether `p` is within the soft limits.
    pub fn in_range(&self, p: i32) -> bool {
        p >= self.min && p <= self.max
    }

    fn plan_pending(&self) -> bool {
        self.target != self.plan.target || self.speed != self.plan.speed || self.dynamics.accel != self.plan.accel
    }

    /// Whether the axis is still travelling or settling.
    pub fn moving(&self) -> bool {
        if self.plan_pending() {
            return self.position != self.target || self.velocity != 0.0;
        }
        let settle = if self.plan.moves {
            f64::from(self.dynamics.settle_ms) / 1000.0
        } else {
            0.0
        };
        (self.elapsed_ms as f64) / 1000.0 < self.plan.duration + settle
    }

    /// Exact motor position, counts (what a perfect encoder would read).
    pub fn motor_position(&self) -> f64 {
        self.motor
    }

    /// The true mechanical (output shaft) position, counts: the motor
    /// position less the backlash the gear has taken up.
    pub fn true_position(&self) -> f64 {
        self.output
    }

    /// What the encoder reports given a standard normal draw `n`: the motor
    /// position plus `n · encoder_sigma`, rounded to whole counts. Without
    /// noise, exactly [`Axis::position`].
    pub fn reading(&self, n: f64) -> i32 {
        if self.dynamics.encoder_sigma == 0.0 {
            return self.position;
        }
        let v = floor(self.motor + n * self.dynamics.encoder_sigma + 0.5);
        clamp_i32(v)
    }

    /// Halt where the axis is now (immediately, whatever the acceleration).
    pub fn stop(&mut self) {
        self.target = self.position;
        self.motor = f64::from(self.position);
        self.velocity = 0.0;
        self.take_up_backlash();
        self.plan = Plan::at_rest(self.position, self.speed, self.dynamics.accel);
        self.elapsed_ms = 0;
    }

    /// Advance by `dt_ms` milliseconds.
    pub fn advance(&mut self, dt_ms: u64) {
        if self.plan_pending() {
            self.plan = Plan::new(self.motor, self.velocity, self.target, self.speed, self.dynamics.accel);
            self.elapsed_ms = 0;
        }
        self.elapsed_ms = self.elapsed_ms.saturating_add(dt_ms);
        let (p, v) = self.plan.at(self.elapsed_ms as f64 / 1000.0);
        let (lo, hi) = (f64::from(self.min), f64::from(self.max));
        self.motor = if p < lo {
            lo
        } else if p > hi {
            hi
        } else {
            p
        };
        self.velocity = v;
        self.take_up_backlash();
        self.position = if self.motor == f64::from(self.target) {
            self.target
        } else {
            // Whole counts still to go, rounded up: the position reaches the
            // target only on arrival.
            let rem = f64::from(self.target) - self.motor;
            let left = ceil(abs(rem) - 1e-6);
            let p = f64::from(self.target) - sign(rem) * left;
            clamp_i32(p).clamp(self.min.min(self.max), self.max.max(self.min))
        };
    }

    fn take_up_backlash(&mut self) {
        let b = self.dynamics.backlash;
        let m = self.motor;
        if self.output > m {
            self.output = m;
        } else if self.output < m - b {
            self.output = m - b;
        }
    }
}

/// A two-axis head with a clock and an encoder-noise generator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Head {
    /// The pan axis.
    pub pan: Axis,
    /// The tilt axis.
    pub tilt: Axis,
    /// Where `home` sends the axes, (pan, tilt) counts.
    pub home: (i32, i32),
    last_ms: Option<u64>,
    rng: u64,
}

impl Head {
    /// A head resting at `home`.
    pub const fn new(pan: Axis, tilt: Axis, home: (i32, i32)) -> Self {
        Self {
            pan,
            tilt,
            home,
            last_ms: None,
            rng: 0,
        }
    }

    /// Seed the encoder noise (the same seed gives the same readings).
    pub fn seed_encoder(&mut self, seed: u64) {
        self.rng = seed;
    }

    /// Whether either axis is travelling or settling.
    pub fn moving(&self) -> bool {
        self.pan.moving() || self.tilt.moving()
    }

    /// Halt both axes.
    pub fn stop(&mut self) {
        self.pan.stop();
        self.tilt.stop();
    }

    /// The pan encoder's reading (with noise, if configured).
    pub fn read_pan(&mut self) -> i32 {
        let n = self.normal(self.pan.dynamics.encoder_sigma);
        self.pan.reading(n)
    }

    /// The tilt encoder's reading (with noise, if configured).
    pub fn read_tilt(&mut self) -> i32 {
        let n = self.normal(self.tilt.dynamics.encoder_sigma);
        self.tilt.reading(n)
    }

    /// A standard normal draw when `sigma` is nonzero (no draw otherwise, so
    /// noiseless heads do not consume the stream): the Irwin–Hall sum of
    /// twelve uniforms less six, of mean 0 and variance exactly 1.
    fn normal(&mut self, sigma: f64) -> f64 {
        if sigma == 0.0 {
            return 0.0;
        }
        let mut s = -6.0;
        for _ in 0..12 {
            s += (splitmix64(&mut self.rng) >> 11) as f64 / (1u64 << 53) as f64;
        }
        s
    }

    /// Advance to `now_ms`; returns true if the head came to rest during
    /// this step (it was moving before and is not now).
    pub fn advance(&mut self, now_ms: u64) -> bool {
        let dt = match self.last_ms {
            Some(last) => now_ms.saturating_sub(last),
            None => 0,
        };
        self.last_ms = Some(now_ms.max(self.last_ms.unwrap_or(0)));
        let was_moving = self.moving();
        self.pan.advance(dt);
        self.tilt.advance(dt);
        was_moving && !self.moving()
    }
}

/// SplitMix64: one step of a tiny, well-mixed 64-bit generator.
fn splitmix64(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

fn abs(x: f64) -> f64 {
    if x < 0.0 { -x } else { x }
}

fn sign(x: f64) -> f64 {
    if x < 0.0 { -1.0 } else { 1.0 }
}

fn min(a: f64, b: f64) -> f64 {
    if a < b { a } else { b }
}

fn max0(x: f64) -> f64 {
    if x > 0.0 { x } else { 0.0 }
}

/// Largest whole number ≤ `x` (for |x| < 2⁶³).
fn floor(x: f64) -> f64 {
    let i = x as i64 as f64;
    if i > x { i - 1.0 } else { i }
}

/// Smallest whole number ≥ `x` (for |x| < 2⁶³).
fn ceil(x: f64) -> f64 {
    let i = x as i64 as f64;
    if i < x { i + 1.0 } else { i }
}

/// √x by Newton's method (x ≥ 0; 0 for anything else).
fn sqrt(x: f64) -> f64 {
    if x.is_nan() || x <= 0.0 {
        return 0.0;
    }
    if x == f64::INFINITY {
        return x;
    }
    let mut r = if x > 1.0 { x } else { 1.0 };
    for _ in 0..200 {
        let next = 0.5 * (r + x / r);
        if next >= r {
            break;
        }
        r = next;
    }
    r
}

fn clamp_i32(v: f64) -> i32 {
    if v >= f64::from(i32::MAX) {
        i32::MAX
    } else if v <= f64::from(i32::MIN) {
        i32::MIN
    } else {
        v as i32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slews_at_speed_and_lands_exactly() {
        // 1000 counts/s: after 250 ms, 250 counts; after 1.1 s, at target.
        let mut a = Axis::new(0, -5000, 5000, 1000);
        a.target = 1000;
        a.advance(250);
        assert_eq!(a.position, 250);
        a.advance(1);
        a.advance(1);
        assert_eq!(a.position, 252);
        a.advance(850);
        assert_eq!(a.position, 1000);
        assert!(!a.moving());
        a.target = -1000;
        a.advance(1500);
        assert_eq!(a.position, -500);
        a.stop();
        a.advance(1000);
        assert_eq!(a.position, -500);
    }

    #[test]
    fn sub_count_progress_accumulates() {
        // 3 counts/s: ten 100 ms steps move 3 counts.
        let mut a = Axis::new(0, -10, 10, 3);
        a.target = 10;
        for _ in 0..10 {
            a.advance(100);
        }
        assert_eq!(a.position, 3);
    }

    #[test]
    fn head_reports_arrival_once() {
        let mut h = Head::new(Axis::new(0, -100, 100, 100), Axis::new(0, -100, 100, 100), (0, 0));
        h.advance(0);
        h.pan.target = 50;
        assert!(!h.advance(100));
        assert!(h.advance(600));
        assert!(!h.advance(700));
        assert_eq!(h.pan.position, 50);
    }

    /// Centidegrees: 90° at 60°/s with 120°/s² and 0.2 s settle. The
    /// trapezoid takes v/a + d/v = 0.5 + 1.5 = 2.0 s, idle at 2.2 s.
    fn trapezoid_axis() -> Axis {
        Axis::new(0, -18_000, 18_000, 6_000).with_dynamics(Dynamics {
            accel: 12_000,
            settle_ms: 200,
            ..Dynamics::default()
        })
    }

    #[test]
    fn trapezoid_reaches_idle_at_the_analytic_time_to_the_millisecond() {
        let mut a = trapezoid_axis();
        a.target = 9_000;
        let mut arrived = None;
        let mut idle = None;
        for ms in 1..=3000u64 {
            a.advance(1);
            if arrived.is_none() && a.position == 9_000 {
                arrived = Some(ms);
            }
            if idle.is_none() && !a.moving() {
                idle = Some(ms);
            }
            // Known points of the profile: 15° after the 0.5 s ramp, 75° at 1.5 s.
            if ms == 500 {
                assert!((a.motor_position() - 1_500.0).abs() < 1e-6, "{}", a.motor_position());
            }
            if ms == 1500 {
                assert!((a.motor_position() - 7_500.0).abs() < 1e-6, "{}", a.motor_position());
            }
        }
        assert_eq!(arrived, Some(2000));
        assert_eq!(idle, Some(2200));
    }

    #[test]
    fn short_move_is_a_triangle() {
        // 10° at 120°/s² never reaches 60°/s: t = 2 √(d/a) = 2 √(1/12) s ≈ 577.35 ms.
        let mut a = trapezoid_axis();
        a.dynamics.settle_ms = 0;
        a.target = 1_000;
        let mut ms = 0;
        while a.position != 1_000 {
            a.advance(1);
            ms += 1;
        }
        assert_eq!(ms, 578);
    }

    #[test]
    fn reversal_mid_move_brakes_then_returns_without_overshooting_limits() {
        let mut a = trapezoid_axis();
        a.dynamics.settle_ms = 0;
        a.target = 18_000;
        a.advance(1000); // 45° at 60°/s... cruising
        a.target = 0;
        let mut peak = a.motor_position();
        for _ in 0..5000 {
            a.advance(1);
            peak = peak.max(a.motor_position());
        }
        // Braking from 60°/s at 120°/s² takes 15° more.
        assert!((peak - (a_at_1s() + 1_500.0)).abs() < 1.0, "{peak}");
        assert_eq!(a.position, 0);
        assert!(!a.moving());
    }

    fn a_at_1s() -> f64 {
        // 15° during the ramp (0.5 s) + 30° cruising (0.5 s at 60°/s).
        4_500.0
    }

    #[test]
    fn backlash_lags_by_its_width_after_positive_moves_only() {
        let mut a = Axis::new(0, -10_000, 10_000, 1_000).with_dynamics(Dynamics {
            backlash: 25.0,
            ..Dynamics::default()
        });
        a.target = 1_000;
        a.advance(5_000);
        assert_eq!(a.position, 1_000);
        assert_eq!(a.true_position(), 975.0);
        a.target = 500;
        a.advance(5_000);
        assert_eq!(a.true_position(), 500.0);
        // A reversal: the first 25 counts of motor travel do not move the output.
        a.target = 520;
        a.advance(5_000);
        assert_eq!(a.true_position(), 500.0);
        a.target = 600;
        a.advance(5_000);
        assert_eq!(a.true_position(), 575.0);
    }

    #[test]
    fn encoder_noise_has_the_configured_sigma_within_5_percent() {
        let mut h = Head::new(
            Axis::new(0, -1_000_000, 1_000_000, 1_000).with_dynamics(Dynamics {
                encoder_sigma: 20.0,
                ..Dynamics::default()
            }),
            Axis::new(0, -10, 10, 1),
            (0, 0),
        );
        h.seed_encoder(42);
        let n = 20_000;
        let (mut s, mut s2) = (0.0, 0.0);
        for _ in 0..n {
            let r = f64::from(h.read_pan());
            s += r;
            s2 += r * r;
        }
        let mean = s / f64::from(n);
        let sd = (s2 / f64::from(n) - mean * mean).sqrt();
        // Rounding adds 1/12 count² of variance: √(400 + 1/12) ≈ 20.002.
        assert!(mean.abs() < 0.5, "mean {mean}");
        assert!((sd / 20.0 - 1.0).abs() < 0.05, "sd {sd}");
        // Noiseless tilt reads exactly.
        assert_eq!(h.read_tilt(), 0);
    }

    #[test]
    fn speed_change_mid_move_replans() {
        let mut a = Axis::new(0, -100_000, 100_000, 1_000);
        a.target = 10_000;
        a.advance(1_000);
        assert_eq!(a.position, 1_000);
        a.speed = 2_000;
        a.advance(1_000);
        assert_eq!(a.position, 3_000);
    }
}
