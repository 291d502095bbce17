//! A run's named frame windows: before the first event, the N frames after each event (the
//! transient), the rest until the next event (the steady state), and overall; summary.json's
//! means and the JOD of each are taken over them.

use serde::Serialize;

use crate::run::Manifest;

/// Frames after an event counted as its transient.
pub const DEFAULT_WINDOW: u32 = 10;

#[derive(Clone, Debug, Serialize)]
pub struct Window {
    pub name: String,
    /// First and last frame, inclusive.
    pub first: u32,
    pub last: u32,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub event: Option<String>,
}

/// The named windows of a run of `frame_count` frames.
pub fn windows(manifest: &Manifest, frame_count: u32, n: u32) -> Vec<Window> {
    let last = frame_count.saturating_sub(1);
    let mut out = Vec::new();
    let events: Vec<_> = manifest.events.iter().filter(|e| e.frame <= last).collect();
    if let Some(first) = events.first()
        && first.frame > 0
    {
        out.push(Window {
            name: "before_first_event".into(),
            first: 0,
            last: first.frame - 1,
            event: None,
        });
    }
    for (i, e) in events.iter().enumerate() {
        let end = events.get(i + 1).map(|next| next.frame.saturating_sub(1)).unwrap_or(last);
        let transient_end = (e.frame + n.max(1) - 1).min(end);
        let label = Some(format!("frame {}: {}", e.frame, e.label));
        out.push(Window {
            name: format!("after_event_{i}"),
            first: e.frame,
            last: transient_end,
            event: label.clone(),
        });
        if transient_end < end {
            out.push(Window {
                name: format!("steady_after_event_{i}"),
                first: transient_end + 1,
                last: end,
                event: label,
            });
        }
    }
    out.push(Window { name: "overall".into(), first: 0, last, event: None });
    out
}
