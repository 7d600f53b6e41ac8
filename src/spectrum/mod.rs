//! Spectral estimation (filled in by the spectrum work).
