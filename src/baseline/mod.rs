//! Baselines the recognizer is compared with: ICP (the paper's Table I) and a Scan Context-style
//! polar descriptor, both written against the plug-in API (`place`).

pub mod icp;
pub mod scan_context;

pub use icp::{IcpConfig, IcpRecognizer};
pub use scan_context::{ScanContextConfig, ScanContextRecognizer};
