//! PHOLD.
