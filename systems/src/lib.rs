//! Per-frame systems tying sim to render, and scenario playback.
