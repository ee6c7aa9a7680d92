//! Baselines the recognizer is compared with (ICP).
