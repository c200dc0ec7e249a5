//! Models for the kernel: the pool objects of the thesis, and PHOLD, the standard benchmark of
//! parallel discrete-event simulators, which keeps the kernel honest.

pub mod phold;
pub mod pool;
pub mod sectored;
