//! The simulated robot: differential drive and route-following controller, LMS200 laser model,
//! odometry error models, pedestrians, seeded random streams, and lap generation.
