//! The smallest terminal the HMI's panel fits in: in a smaller one the panel is not drawn
//! cut (rows r2..r4, the candidates or the keys silently missing), the screen says so
//! instead ([`draw_if_too_small`]).

use ratatui::layout::Rect;
use ratatui::widgets::{Paragraph, Wrap};
use ratatui::Frame;

/// Columns the panel needs: the candidates' and the operating point's halves side by side.
pub const MIN_WIDTH: u16 = 80;
/// Rows the panel needs: title 1, lamps 2, residuals r1..r4 5, candidates 6, strip chart
/// at least 5, controls 1, notes 2, keys 1.
pub const MIN_HEIGHT: u16 = 23;

/// The note for a `width` x `height` terminal too small for the panel ("terminal 60x15 is
/// too small: need 80x23 ..."), `None` when the panel fits.
pub fn too_small(width: u16, height: u16) -> Option<String> {
    (width < MIN_WIDTH || height < MIN_HEIGHT).then(|| {
        format!(
            "terminal {width}x{height} is too small: need {MIN_WIDTH}x{MIN_HEIGHT} \
             (enlarge it; q quits)"
        )
    })
}

/// Draws [`too_small`]'s note over the whole frame when the panel does not fit (wrapped to
/// the width); whether it did, in which case the panel must not be drawn.
pub fn draw_if_too_small(frame: &mut Frame) -> bool {
    let area: Rect = frame.area();
    let Some(note) = too_small(area.width, area.height) else {
        return false;
    };
    frame.render_widget(Paragraph::new(note).wrap(Wrap { trim: true }), area);
    true
}
