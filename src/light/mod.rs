//! Light sources: area lights and environments, with sampling for next-event estimation.
