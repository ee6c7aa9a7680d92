//! ROS 2 bags: MCAP files of CDR messages (`bag`), the messages placewords exchanges (`msg`) and
//! their serialization (`cdr`). docs/ros2.md shows how to open and replay them.

pub mod bag;
pub mod cdr;
pub mod msg;
