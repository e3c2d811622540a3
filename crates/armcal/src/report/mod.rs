//! Self-contained HTML reports: figures as inline SVG (plotters, embedded font) and a 3D
//! view of the cell drawn in the browser from inline data. One file, no network fetches.

pub mod cell_view;
