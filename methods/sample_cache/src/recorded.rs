//! What the sample cache records besides every method's numbers.

use frame::method::Statistic;

pub const STATISTICS: &[Statistic] =
    &[Statistic::frames("PrimaryRays", "primary_rays", "primary rays traced", "rays")];
