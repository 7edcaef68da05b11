//! The scheduler: a pure function of the plan, the site and the time (being written).
