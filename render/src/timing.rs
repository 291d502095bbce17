//! Time per pass, one helper for every method: GPU timestamp queries (one begin/end pair per
//! compute pass) where the adapter has TIMESTAMP_QUERY, else the wall time of each pass
//! submitted on its own and waited for with a device poll. Never a whole frame under one name.

use crate::error::RenderError;
use crate::gpu::Gpu;
use crate::readback::Staging;
use std::time::Instant;

/// Which clock measured a [`PassTiming`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Clock {
    /// GPU timestamp queries around the pass: device time only.
    Gpu,
    /// CPU wall time from submitting the pass alone to the device poll that saw it finish
    /// (includes submission and driver overhead).
    Wall,
}

impl Clock {
    /// `gpu` or `wall`: the prefix of the pass columns in frames.csv.
    pub fn name(self) -> &'static str {
        match self {
            Clock::Gpu => "gpu",
            Clock::Wall => "wall",
        }
    }
}

/// Time of one pass of one frame.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PassTiming {
    pub pass: String,
    pub ms: f64,
    pub clock: Clock,
}

/// A query set with a begin/end pair for each of `passes` passes, and buffers to read it back.
pub struct PassTimestamps {
    query_set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    readback: Staging,
    passes: u32,
    period_ns: f64,
}

impl PassTimestamps {
    /// `None` where the adapter has no timestamp queries.
    pub fn new(gpu: &Gpu, passes: u32) -> Option<Self> {
        if !gpu.has_timestamps() || passes == 0 {
            return None;
        }
        let count = 2 * passes;
        let query_set = gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("pass timestamps"),
            ty: wgpu::QueryType::Timestamp,
            count,
        });
        let size = count as u64 * 8;
        let resolve = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timestamp resolve"),
            size,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let readback = Staging::new(gpu, "timestamps", size);
        Some(Self {
            query_set,
            resolve,
            readback,
            passes,
            period_ns: gpu.queue.get_timestamp_period() as f64,
        })
    }

    /// Timestamp writes bracketing pass number `pass`.
    pub fn writes(&self, pass: u32) -> wgpu::ComputePassTimestampWrites<'_> {
        assert!(pass < self.passes, "pass {pass} of {}", self.passes);
        wgpu::ComputePassTimestampWrites {
            query_set: &self.query_set,
            beginning_of_pass_write_index: Some(2 * pass),
            end_of_pass_write_index: Some(2 * pass + 1),
        }
    }

    /// Records the resolve and the copy to the readback buffer; call after the last pass.
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.resolve_query_set(&self.query_set, 0..2 * self.passes, &self.resolve, 0);
        self.readback.record(encoder, &self.resolve, 0);
    }

    /// Milliseconds of each pass; call after the submission holding `resolve` has completed.
    pub fn read(&self, gpu: &Gpu) -> Result<Vec<f64>, RenderError> {
        let ticks: Vec<u64> = self.readback.read(gpu)?;
        Ok(ticks
            .chunks_exact(2)
            .map(|p| p[1].saturating_sub(p[0]) as f64 * self.period_ns * 1e-6)
            .collect())
    }
}

/// The named passes of one method and the clock that times them.
pub struct PassTimer {
    names: Vec<String>,
    timestamps: Option<PassTimestamps>,
}

impl PassTimer {
    /// Timestamp queries where the adapter has them, else wall time per pass.
    pub fn new(gpu: &Gpu, names: &[&str]) -> Self {
        Self {
            names: names.iter().map(|n| n.to_string()).collect(),
            timestamps: PassTimestamps::new(gpu, names.len() as u32),
        }
    }

    /// Wall time per pass even where timestamps exist (tests of the fallback; comparing clocks).
    pub fn wall(names: &[&str]) -> Self {
        Self { names: names.iter().map(|n| n.to_string()).collect(), timestamps: None }
    }

    pub fn clock(&self) -> Clock {
        if self.timestamps.is_some() { Clock::Gpu } else { Clock::Wall }
    }

    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Starts a frame's command recording.
    pub fn begin<'a>(&'a self, gpu: &'a Gpu, label: &str) -> TimedFrame<'a> {
        TimedFrame {
            timer: self,
            gpu,
            encoder: new_encoder(gpu, label),
            wall: vec![None; self.names.len()],
            used: vec![false; self.names.len()],
        }
    }
}

fn new_encoder(gpu: &Gpu, label: &str) -> wgpu::CommandEncoder {
    gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) })
}

fn wait(gpu: &Gpu) -> Result<(), RenderError> {
    gpu.device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| RenderError::Readback {
        what: "pass submission".into(),
        reason: e.to_string(),
    })?;
    Ok(())
}

/// One frame's recording: untimed commands go to [`Self::encoder`], each named pass through
/// [`Self::pass`]; [`Self::submit`] runs what is left, waits, and returns the pass times.
pub struct TimedFrame<'a> {
    timer: &'a PassTimer,
    gpu: &'a Gpu,
    encoder: wgpu::CommandEncoder,
    wall: Vec<Option<f64>>,
    used: Vec<bool>,
}

impl TimedFrame<'_> {
    /// The encoder for untimed work (clears, copies) in order with the passes.
    pub fn encoder(&mut self) -> &mut wgpu::CommandEncoder {
        &mut self.encoder
    }

    /// Records pass `index` (of the timer's names) as one compute pass. With the wall clock the
    /// commands recorded so far are submitted and waited for first, then the pass alone.
    pub fn pass(
        &mut self,
        index: usize,
        record: impl FnOnce(&mut wgpu::ComputePass<'_>),
    ) -> Result<(), RenderError> {
        let name = &self.timer.names[index];
        assert!(!self.used[index], "pass {name} recorded twice in one frame");
        self.used[index] = true;
        match &self.timer.timestamps {
            Some(t) => {
                let mut pass = self.encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some(name),
                    timestamp_writes: Some(t.writes(index as u32)),
                });
                record(&mut pass);
            }
            None => {
                let before = std::mem::replace(&mut self.encoder, new_encoder(self.gpu, name));
                self.gpu.queue.submit([before.finish()]);
                wait(self.gpu)?;
                let start = Instant::now();
                {
                    let mut pass = self.encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                        label: Some(name),
                        timestamp_writes: None,
                    });
                    record(&mut pass);
                }
                let this = std::mem::replace(&mut self.encoder, new_encoder(self.gpu, name));
                self.gpu.queue.submit([this.finish()]);
                wait(self.gpu)?;
                self.wall[index] = Some(start.elapsed().as_secs_f64() * 1e3);
            }
        }
        Ok(())
    }

    /// Submits the rest, waits for the device, and returns the times of the passes recorded,
    /// in the timer's order.
    pub fn submit(mut self) -> Result<Vec<PassTiming>, RenderError> {
        if let Some(t) = &self.timer.timestamps {
            t.resolve(&mut self.encoder);
        }
        self.gpu.queue.submit([self.encoder.finish()]);
        wait(self.gpu)?;
        let gpu_ms = match &self.timer.timestamps {
            Some(t) => Some(t.read(self.gpu)?),
            None => None,
        };
        let clock = self.timer.clock();
        Ok((0..self.timer.names.len())
            .filter(|&i| self.used[i])
            .map(|i| PassTiming {
                pass: self.timer.names[i].clone(),
                ms: gpu_ms.as_ref().map_or_else(|| self.wall[i].unwrap_or(0.0), |g| g[i]),
                clock,
            })
            .collect())
    }
}

/// Adds the times of passes of the same name (a pass split over several submissions).
pub fn merge(into: &mut Vec<PassTiming>, more: Vec<PassTiming>) {
    for t in more {
        match into.iter_mut().find(|u| u.pass == t.pass) {
            Some(u) => u.ms += t.ms,
            None => into.push(t),
        }
    }
}
