//! Which recorded frames a gate averages: before or after an event, a steady state, or all.
//! Events are numbered in the order of the scenario's `events_summary` (scripted events and
//! one-shot rotations); their frames count recorded frames (warm-up frames subtracted).

use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Window {
    /// Every recorded frame.
    Overall,
    /// `Before(event: 0)`: the frames before event `event`.
    Before { event: usize },
    /// `After(event: 0, frames: 3)`: the event's frame and the `frames - 1` after it (the transient).
    After { event: usize, frames: u32 },
    /// `Steady(event: 0, skip: 2)`: from `skip` frames after event `event` (no `event`: after the
    /// first frame) to the next event or the end; the state a method settles in.
    Steady {
        #[serde(default)]
        event: Option<usize>,
        skip: u32,
    },
    /// `Around(event: 0, from: -4, to: 0)`: the frames `event + from` to `event + to`, the last
    /// excluded (here the 4 frames before the event), clipped to the run.
    Around { event: usize, from: i32, to: i32 },
}

impl Window {
    pub fn name(&self) -> String {
        match self {
            Window::Overall => "overall".into(),
            Window::Before { event: e } => format!("before_event_{e}"),
            Window::After { event: e, frames: n } => format!("after_event_{e}({n})"),
            Window::Steady { event: None, skip } => format!("steady(+{skip})"),
            Window::Steady { event: Some(e), skip } => format!("steady_after_event_{e}(+{skip})"),
            Window::Around { event: e, from, to } => format!("event_{e}{from:+}..{to:+}"),
        }
    }

    /// Why the window holds no frame in any run, if it holds none: an empty window judges
    /// nothing.
    pub fn empty(&self) -> Option<String> {
        match *self {
            Window::After { frames: 0, .. } => {
                Some("frames: 0 is an empty window; expected at least 1 frame".into())
            }
            Window::Around { from, to, .. } if from >= to => Some(format!(
                "from: {from} is not before to: {to} (the end is excluded), so the window is empty; expected from < to"
            )),
            _ => None,
        }
    }

    /// The event this window needs, if any.
    pub fn event(&self) -> Option<usize> {
        match self {
            Window::Overall | Window::Steady { event: None, .. } => None,
            Window::Before { event: e }
            | Window::After { event: e, .. }
            | Window::Steady { event: Some(e), .. }
            | Window::Around { event: e, .. } => Some(*e),
        }
    }

    /// The recorded frames `first..end` of a run of `frames` frames with events at `events`
    /// (recorded frames, ascending); `None` when the window's event is not in the run.
    pub fn frames(&self, frames: u32, events: &[u32]) -> Option<std::ops::Range<u32>> {
        let event = |e: usize| events.get(e).copied();
        let next = |e: usize| events.get(e + 1).copied().unwrap_or(frames);
        let range = match *self {
            Window::Overall => 0..frames,
            Window::Before { event: e } => 0..event(e)?,
            Window::After { event: e, frames: n } => event(e)?..(event(e)? + n).min(frames),
            Window::Steady { event: None, skip } => {
                skip.min(frames)..events.first().copied().unwrap_or(frames)
            }
            Window::Steady { event: Some(e), skip } => (event(e)? + skip).min(frames)..next(e),
            Window::Around { event: e, from, to } => {
                let start = event(e)? as i64;
                let at = |offset: i32| (start + offset as i64).clamp(0, frames as i64) as u32;
                at(from)..at(to).max(at(from))
            }
        };
        Some(range)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn windows_around_events() {
        let events = [4, 10];
        assert_eq!(Window::Overall.frames(16, &events), Some(0..16));
        assert_eq!(Window::Before { event: 0 }.frames(16, &events), Some(0..4));
        assert_eq!(Window::After { event: 0, frames: 3 }.frames(16, &events), Some(4..7));
        assert_eq!(Window::After { event: 1, frames: 30 }.frames(16, &events), Some(10..16));
        assert_eq!(Window::Steady { event: None, skip: 1 }.frames(16, &events), Some(1..4));
        assert_eq!(Window::Steady { event: Some(0), skip: 2 }.frames(16, &events), Some(6..10));
        assert_eq!(Window::Steady { event: Some(1), skip: 2 }.frames(16, &events), Some(12..16));
        assert_eq!(Window::Before { event: 2 }.frames(16, &events), None);
        // Relative to an event, either side, clipped to the run.
        let around = |event, from, to| Window::Around { event, from, to }.frames(16, &events);
        assert_eq!(around(0, -4, 0), Some(0..4));
        assert_eq!(around(0, -2, 3), Some(2..7));
        assert_eq!(around(1, 2, 4), Some(12..14));
        assert_eq!(around(1, 4, 12), Some(14..16));
        assert_eq!(around(0, -8, -6), Some(0..0));
        assert_eq!(around(2, 0, 1), None);
    }
}
