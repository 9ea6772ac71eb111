//! Image input and output: EXR with AOVs and metadata, tone-mapped PNG, atomic writes.
