//! `host-sim campaign`: shards that merge bit for bit whatever the sharding, restart after a
//! kill, the merge's refusals, the campaign file's errors, worst cases that replay bit for bit,
//! the engines' environment, and the shipped Kubernetes manifest.
//!
//! One test binary, a file per behaviour: what a run draws ([`draws`]), sharding and its
//! bit-identical merge ([`sharding`]), resuming a shard ([`resume`]), the merge's checks and
//! verdict ([`merge`]), the campaign file and `plan` ([`file`]), worst cases ([`worst`]), the
//! shard from the engines' environment ([`engines`]) and Kubernetes ([`k8s`]).

mod draws;
mod engines;
mod file;
mod forged;
mod k8s;
mod merge;
mod resume;
mod sharding;
mod support;
mod worst;
