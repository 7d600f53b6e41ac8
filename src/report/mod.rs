//! SVG figures (filled in by the plotting work).
