//! Text of the PNG figures, drawn glyph by glyph at each glyph's own side bearing.
//!
//! plotters' `ab_glyph` text path puts every glyph's bitmap at the pen position without the
//! glyph's left side bearing, so letters sit unevenly ("m ax" for "max"). [`GlyphText`]
//! wraps a pixel backend and draws text itself, with the same layout box, anchor and
//! rotation as plotters (so figure layouts do not move); everything else passes through.

use ab_glyph::{point, Font, FontRef, GlyphId, PxScale, ScaleFont};
use plotters_backend::text_anchor::{HPos, VPos};
use plotters_backend::{
    BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingBackend, DrawingErrorKind,
};
use std::sync::OnceLock;

/// The bundled font (DejaVu Sans), the only one figures use.
pub const DEJAVU_SANS: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");

fn font() -> &'static FontRef<'static> {
    static FONT: OnceLock<FontRef<'static>> = OnceLock::new();
    FONT.get_or_init(|| {
        FontRef::try_from_slice(DEJAVU_SANS)
            .unwrap_or_else(|_| panic!("the bundled font is a valid TTF"))
    })
}

/// A pixel backend whose text is drawn with correct glyph placement.
pub struct GlyphText<B> {
    inner: B,
}

impl<B: DrawingBackend> GlyphText<B> {
    /// Wrap `inner`.
    pub fn new(inner: B) -> Self {
        GlyphText { inner }
    }
}

/// Ink of `text` at `size` px as (x, y, coverage) with x from the pen's start and y from the
/// top of plotters' layout box (baseline at size/2, as plotters places it).
pub(crate) fn ink(text: &str, size: f64) -> Vec<(i32, i32, f32)> {
    let font = font();
    let scale = PxScale::from(size as f32);
    let scaled = font.as_scaled(scale);
    let baseline = (size / 2.0) as f32;
    let mut pen = 0f32;
    let mut prev: Option<GlyphId> = None;
    let mut out = Vec::new();
    for c in text.chars() {
        let id = scaled.glyph_id(c);
        if let Some(p) = prev {
            pen += scaled.kern(p, id);
        }
        let glyph = id.with_scale_and_position(scale, point(pen, baseline));
        if let Some(outline) = font.outline_glyph(glyph) {
            // px_bounds are absolute (pen and side bearing included): this is the fix.
            let b = outline.px_bounds();
            outline.draw(|x, y, cov| {
                if cov > 0.0 {
                    out.push((b.min.x as i32 + x as i32, b.min.y as i32 + y as i32, cov));
                }
            });
        }
        pen += scaled.h_advance(id);
        prev = Some(id);
    }
    out
}

impl<B: DrawingBackend> DrawingBackend for GlyphText<B> {
    type ErrorType = B::ErrorType;

    fn get_size(&self) -> (u32, u32) {
        self.inner.get_size()
    }
    fn ensure_prepared(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.ensure_prepared()
    }
    fn present(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.present()
    }
    fn draw_pixel(
        &mut self,
        point: BackendCoord,
        color: BackendColor,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_pixel(point, color)
    }
    fn draw_line<S: BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_line(from, to, style)
    }
    fn draw_rect<S: BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_rect(upper_left, bottom_right, style, fill)
    }
    fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_path(path, style)
    }
    fn draw_circle<S: BackendStyle>(
        &mut self,
        center: BackendCoord,
        radius: u32,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_circle(center, radius, style, fill)
    }
    fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        vert: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.fill_polygon(vert, style)
    }
    fn blit_bitmap(
        &mut self,
        pos: BackendCoord,
        size: (u32, u32),
        src: &[u8],
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.blit_bitmap(pos, size, src)
    }

    fn draw_text<TStyle: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &TStyle,
        pos: BackendCoord,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        let color = style.color();
        if color.alpha == 0.0 {
            return Ok(());
        }
        // plotters' own layout box (advances and kerning), so anchors and the space the
        // chart set aside for labels stay as they were.
        let ((min_x, min_y), (max_x, max_y)) = style
            .layout_box(text)
            .map_err(|e| DrawingErrorKind::FontError(Box::new(e)))?;
        let (width, height) = (max_x - min_x, max_y - min_y);
        let dx = match style.anchor().h_pos {
            HPos::Left => 0,
            HPos::Center => -width / 2,
            HPos::Right => -width,
        };
        let dy = match style.anchor().v_pos {
            VPos::Top => 0,
            VPos::Center => -height / 2,
            VPos::Bottom => -height,
        };
        let rotate = style.transform();
        let (w, h) = self.get_size();
        for (x, y, cov) in ink(text, style.size()) {
            let (rx, ry) = rotate.transform(x + dx - min_x, y + dy - min_y);
            let (px, py) = (pos.0 + rx, pos.1 + ry);
            if px >= 0 && py >= 0 && px < w as i32 && py < h as i32 {
                self.inner.draw_pixel((px, py), color.mix(f64::from(cov)))?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Columns holding ink, split into runs (one run per glyph for letters without
    /// overlapping boxes).
    fn ink_runs(text: &str, size: f64) -> Vec<(i32, i32)> {
        let mut cols: Vec<i32> = ink(text, size)
            .into_iter()
            .filter(|&(_, _, c)| c > 0.5)
            .map(|(x, _, _)| x)
            .collect();
        cols.sort_unstable();
        cols.dedup();
        let mut runs: Vec<(i32, i32)> = Vec::new();
        for x in cols {
            match runs.last_mut() {
                Some(r) if x == r.1 + 1 => r.1 = x,
                _ => runs.push((x, x)),
            }
        }
        runs
    }

    /// The ink gap between two glyphs is the font's right side bearing of the first plus
    /// the left side bearing of the second. DejaVu Sans (read with fontTools): 'm' advance
    /// 1995 units, ink x 186…1821; 'a' advance 1255, ink x 123…1069; ascent 1901, descent
    /// −483 (ab_glyph's pixel size is ascent − descent = 2384 units), no kerning pair. At
    /// 200 px: gap (1995 − 1821 + 123)·200/2384 = 24.9 px; plotters' own path drew it
    /// (186 − 123)·200/2384 = 5.3 px wider. ±1.5 px: each run's edges are rounded to whole
    /// pixels at half coverage.
    #[test]
    fn glyphs_sit_at_their_side_bearings() {
        let size = 200.0;
        let px_per_unit = size / (1901.0 + 483.0);
        let runs = ink_runs("ma", size);
        assert_eq!(runs.len(), 2, "two separate glyphs: {runs:?}");
        let gap = f64::from(runs[1].0 - runs[0].1 - 1);
        let expected = (1995.0 - 1821.0 + 123.0) * px_per_unit;
        assert!(
            (gap - expected).abs() <= 1.5,
            "gap {gap} px against {expected:.1} px from the font's metrics"
        );
        // The first glyph starts at its own left side bearing.
        let lsb = 186.0 * px_per_unit;
        let start = f64::from(runs[0].0);
        assert!(
            (start - lsb).abs() <= 1.5,
            "m starts at {start} px against {lsb:.1}"
        );
    }
}
