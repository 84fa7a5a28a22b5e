//! Scene files (RON): datasets, appearances, camera and the frames to capture.
