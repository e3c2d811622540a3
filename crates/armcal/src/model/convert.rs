//! Conversions between link conventions (DH ↔ modified DH, any chain → zero-reference, zero-reference → DH per book §6.3.4), exact in forward kinematics.
