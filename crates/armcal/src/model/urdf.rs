//! URDF import and export (urdf-rs): joints ↔ general frames.
