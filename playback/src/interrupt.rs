//! Stopping a run between frames. SIGINT and SIGTERM set a flag that the frame loop reads after
//! each frame, so the frame on hand is finished and written and the run is marked incomplete; a
//! second signal ends the process at once (exit code 130), for a frame that takes too long.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};

use anyhow::Result;
use signal_hook::consts::{SIGINT, SIGTERM};

/// Exit code of a run stopped by a signal (128 + SIGINT, as shells report it).
pub const EXIT_CODE: u8 = 130;

fn flag() -> &'static Arc<AtomicBool> {
    static FLAG: OnceLock<Arc<AtomicBool>> = OnceLock::new();
    FLAG.get_or_init(|| Arc::new(AtomicBool::new(false)))
}

/// Routes SIGINT and SIGTERM to the flag (the commands that play runs call it; the others keep
/// the default of ending at once).
pub fn install() -> Result<()> {
    for signal in [SIGINT, SIGTERM] {
        // Registered first, so it sees the flag as it was before this signal set it.
        signal_hook::flag::register_conditional_shutdown(signal, EXIT_CODE.into(), flag().clone())?;
        signal_hook::flag::register(signal, flag().clone())?;
    }
    Ok(())
}

/// Whether a stop was asked for.
pub fn requested() -> bool {
    flag().load(Ordering::Relaxed)
}

/// What a run stopped by a signal returns: it wrote every frame up to `last_complete_frame`
/// (none when it stopped in the warm-up) and marked itself incomplete.
#[derive(Debug)]
pub struct Interrupted {
    pub folder: PathBuf,
    pub last_complete_frame: Option<u32>,
}

impl std::fmt::Display for Interrupted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let done = match self.last_complete_frame {
            Some(n) => format!("frames 0 to {n} are written"),
            None => "no recorded frame was reached".into(),
        };
        write!(
            f,
            "interrupted: {done}; {} is marked incomplete. Continue it with `flicker run --resume {}`",
            self.folder.display(),
            self.folder.display()
        )
    }
}

impl std::error::Error for Interrupted {}
