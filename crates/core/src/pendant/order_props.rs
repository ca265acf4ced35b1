//! What the pendant shows is what the line carries: random per-frame input scripts run
//! through the pendant, both link cores and both simulators on a virtual clock.
