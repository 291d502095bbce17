//! GPU faults as errors: wgpu reports an out-of-memory or validation error through the device's
//! error handler, whose default panics, and a lost device through its lost callback. A run
//! sends them to a [`FaultSink`] instead and ends with an error that names the pass (wgpu's
//! label of the object at fault) and the size.

use std::sync::{Arc, Mutex};

use crate::gpu::{Gpu, GpuError};

/// The first uncaptured error of a device since the last [`FaultSink::take`] (WebGPU keeps the
/// first: the later ones follow from the object it left invalid).
#[derive(Clone, Default)]
pub struct FaultSink(Arc<Mutex<Option<String>>>);

impl FaultSink {
    /// The fault caught since the last call, if any (and clears it).
    pub fn take(&self) -> Option<String> {
        self.0.lock().unwrap_or_else(|e| e.into_inner()).take()
    }

    /// An error naming `pass` and `size` if a fault was caught since the last check.
    pub fn check(&self, pass: &str, size: &str) -> Result<(), GpuError> {
        match self.take() {
            None => Ok(()),
            Some(message) => Err(GpuError::Fault { pass: pass.into(), size: size.into(), message }),
        }
    }
}

/// The kind of a wgpu error and its whole chain: wgpu's context ("In Device::create_buffer,
/// label = 'NAME'") names the object, and a limit's error the bytes asked for.
pub fn describe(error: &wgpu::Error) -> String {
    let (kind, text) = match error {
        // Its description is "Out of Memory" alone: the chain holds the object's label.
        wgpu::Error::OutOfMemory { .. } => {
            let mut chain = Vec::new();
            let mut source = std::error::Error::source(error);
            while let Some(e) = source {
                chain.push(e.to_string());
                source = e.source();
            }
            ("out of memory", chain.join(": "))
        }
        wgpu::Error::Validation { description, .. } => ("validation error", description.clone()),
        wgpu::Error::Internal { description, .. } => ("internal error", description.clone()),
    };
    // wgpu's description: a heading, "Caused by:", then the chain one level per line.
    let lines: Vec<&str> = text
        .lines()
        .map(str::trim)
        .filter(|l| {
            !l.is_empty() && !["Validation Error", "Internal error", "Caused by:"].contains(l)
        })
        .collect();
    format!("GPU {kind}: {}", lines.join(": "))
}

impl Gpu {
    /// Sends this device's errors outside an error scope to the returned sink instead of wgpu's
    /// panicking default; whoever calls this checks the sink after each step.
    pub fn catch_faults(&self) -> FaultSink {
        let sink = FaultSink::default();
        let first = sink.0.clone();
        self.device.on_uncaptured_error(Arc::new(move |error: wgpu::Error| {
            let mut first = first.lock().unwrap_or_else(|e| e.into_inner());
            if first.is_none() {
                *first = Some(describe(&error));
            }
        }));
        // A lost device (a driver reset, a removed GPU, `destroy`) fails every later call:
        // its cause is the fault to report, not the errors that follow from it.
        let lost = sink.0.clone();
        self.device.set_device_lost_callback(move |reason, message| {
            let mut first = lost.lock().unwrap_or_else(|e| e.into_inner());
            let text = format!("GPU device lost ({reason:?}): {message}");
            match first.as_mut() {
                Some(earlier) if !earlier.starts_with("GPU device lost") => {
                    *earlier = format!("{text}; then {earlier}")
                }
                Some(_) => {}
                None => *first = Some(text),
            }
        });
        sink
    }
}
