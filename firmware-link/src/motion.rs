//! The motion model of an emulated pan-tilt head, shared by every head
//! emulator. Positions are integer counts of the protocol's own unit
//! (µrad for campanile-link, 1/100° for Pelco-D, PTU positions for FLIR).
//!
//! Each axis slews at constant speed towards its target (acceleration is
//! stored by the protocols but not simulated) and stops exactly on it.

/// One axis: position, target, soft limits and slew speed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Axis {
    /// Current position, counts.
    pub position: i32,
    /// Commanded position, counts.
    pub target: i32,
    /// Lowest allowed position, counts.
    pub min: i32,
    /// Highest allowed position, counts.
    pub max: i32,
    /// Slew speed, counts per second (0 means "instantaneous").
    pub speed: u32,
    /// Sub-count progress, counts × 1000.
    frac: i64,
}

impl Axis {
    /// An axis at `home`, with limits and speed.
    pub const fn new(home: i32, min: i32, max: i32, speed: u32) -> Self {
        Self {
            position: home,
            target: home,
            min,
            max,
            speed,
            frac: 0,
        }
    }

    /// Whether `p` is within the soft limits.
    pub fn in_range(&self, p: i32) -> bool {
        p >= self.min && p <= self.max
    }

    /// Whether the axis is still travelling.
    pub fn moving(&self) -> bool {
        self.position != self.target
    }

    /// Halt where the axis is now.
    pub fn stop(&mut self) {
        self.target = self.position;
        self.frac = 0;
    }

    /// Advance by `dt_ms` milliseconds.
    pub fn advance(&mut self, dt_ms: u64) {
        if self.position == self.target {
            self.frac = 0;
            return;
        }
        if self.speed == 0 {
            self.position = self.target;
            return;
        }
        let dist = i64::from(self.target) - i64::from(self.position);
        let travel = i64::from(self.speed)
            .saturating_mul(i64::try_from(dt_ms).unwrap_or(i64::MAX))
            .saturating_add(self.frac);
        let whole = travel / 1000;
        if whole >= dist.abs() {
            self.position = self.target;
            self.frac = 0;
        } else {
            self.frac = travel % 1000;
            let step = if dist > 0 { whole } else { -whole };
            // |step| < |dist| ≤ 2^32, so the sum stays between position and target.
            self.position = (i64::from(self.position) + step) as i32;
        }
    }
}

/// A two-axis head with a clock.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Head {
    /// The pan axis.
    pub pan: Axis,
    /// The tilt axis.
    pub tilt: Axis,
    /// Where `home` sends the axes, (pan, tilt) counts.
    pub home: (i32, i32),
    last_ms: Option<u64>,
}

impl Head {
    /// A head resting at `home`.
    pub const fn new(pan: Axis, tilt: Axis, home: (i32, i32)) -> Self {
        Self {
            pan,
            tilt,
            home,
            last_ms: None,
        }
    }

    /// Whether either axis is travelling.
    pub fn moving(&self) -> bool {
        self.pan.moving() || self.tilt.moving()
    }

    /// Halt both axes.
    pub fn stop(&mut self) {
        self.pan.stop();
        self.tilt.stop();
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
}
