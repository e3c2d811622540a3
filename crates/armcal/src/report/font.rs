//! The font the figures are laid out with: DejaVu Sans, embedded in the library
//! (`assets/DejaVuSans.ttf`, Bitstream Vera licence: free to embed and redistribute, see
//! `assets/DejaVuSans-LICENSE.txt`), so plotting needs no system font library. plotters
//! measures text with it (its `ab_glyph` feature); the SVG text names the generic family
//! `sans-serif`, which the browser draws with its own sans-serif face.

use crate::Error;
use plotters::style::{register_font, FontStyle};
use std::sync::OnceLock;

/// DejaVu Sans 2.37, unmodified.
static DEJAVU_SANS: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");

/// The family name the figures use.
pub const FAMILY: &str = "sans-serif";

/// Registers the embedded font with plotters (once per process).
pub fn ensure_registered() -> Result<(), Error> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok =
        *REGISTERED.get_or_init(|| register_font(FAMILY, FontStyle::Normal, DEJAVU_SANS).is_ok());
    if ok {
        Ok(())
    } else {
        Err(Error::Output(
            "the embedded figure font (DejaVu Sans) could not be read".into(),
        ))
    }
}
