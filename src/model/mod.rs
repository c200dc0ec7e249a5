//! The pool objects of the thesis as models of the [`pdes_kernel`] crate: balls, cushions,
//! pockets and corners exchanging messages on a plain table (thesis fig. 3), and the same with
//! sectors relaying news (fig. 14).

pub mod pool;
pub mod sectored;
