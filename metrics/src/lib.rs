//! Image metrics for temporal stability and accuracy.
