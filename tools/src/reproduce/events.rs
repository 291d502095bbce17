//! Windows relative to a scenario's events (`After(event: 1, frames: 4)`, `Around(event: 0,
//! from: -4, to: 0)`), checked when the claims file is loaded: at every scale (a smaller scale
//! may record fewer frames and so lose an event) the case's scenario has the event and the
//! window holds at least one recorded frame. Events are numbered as the suite numbers them
//! (`suite::window`): the scenario's scripted events and one-shot rotations in frame order,
//! events at one frame counted once, warm-up frames subtracted.

use sim::Scenario;

use crate::suite::window::Window;

/// A case's recorded frames and event frames at each scale.
#[derive(Clone, Debug, Default)]
pub struct CaseEvents {
    /// (scale, recorded frames, event frames); empty for a computed case (no frames, no events).
    scales: Vec<(&'static str, u32, Vec<u32>)>,
    /// The scenario's events as `frame N: what`, for the error.
    listing: Vec<String>,
}

impl CaseEvents {
    /// The events of `scenario` at each of a case's scales, given as (scale, its `frames`
    /// override).
    pub fn of(scenario: &Scenario, scales: [(&'static str, Option<u32>); 3]) -> CaseEvents {
        let scales = scales
            .into_iter()
            .map(|(name, frames)| {
                let mut s = scenario.clone();
                s.frames = frames.unwrap_or(s.frames);
                (name, s.frames, crate::suite::run::event_frames(&s))
            })
            .collect();
        let listing =
            scenario.events_summary().into_iter().map(|(f, what)| format!("frame {f}: {what}"));
        CaseEvents { scales, listing: listing.collect() }
    }

    /// Whether `window` can be read from the case at every scale; else what is wrong.
    pub fn check(&self, window: &Window, case: &str) -> Result<(), String> {
        let name = window.name();
        if let Window::Around { from, to, .. } = window
            && from >= to
        {
            return Err(format!(
                "window {name}: from {from} is not before to {to}; expected e.g. Around(event: 0, from: -4, to: 0)"
            ));
        }
        let Some(event) = window.event() else { return Ok(()) };
        if self.scales.is_empty() {
            return Err(format!(
                "window {name} needs event {event}, but case '{case}' is computed and has no events; expected window: Overall"
            ));
        }
        for (scale, frames, events) in &self.scales {
            let listed =
                if self.listing.is_empty() { "none".to_string() } else { self.listing.join("; ") };
            match window.frames(*frames, events) {
                None => {
                    return Err(format!(
                        "window {name} needs event {event} of case '{case}', but at {scale} scale its scenario has {} event(s) in its {frames} recorded frames (at recorded frames {events:?}; the scenario's events: {listed}); events count from 0",
                        events.len()
                    ));
                }
                Some(r) if r.is_empty() => {
                    return Err(format!(
                        "window {name} holds no recorded frame of case '{case}' at {scale} scale ({frames} recorded frames, events at {events:?}); expected a window inside the run"
                    ));
                }
                Some(_) => {}
            }
        }
        Ok(())
    }
}
