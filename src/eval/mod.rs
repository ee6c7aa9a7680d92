//! Evaluation: ground truth pairs, precision and recall, sweeps and the paper's Table I.
