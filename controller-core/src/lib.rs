#![no_std]
#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]

pub mod allocation;
pub mod math;
pub mod trajectory;
