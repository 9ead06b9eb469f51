//! Text in the PNG charts, placed glyph by glyph from the outlines of the bundled font.
//!
//! Plotters' own bitmap text starts each glyph's ink at the pen, dropping the glyph's left side
//! bearing, so a wide bearing (`m`, `×`, `k`) opens a gap after the glyph: "m edian", "40× 40".
//! [`Glyphs`] wraps a backend and draws text where the SVG charts put it: at the same em size
//! (plotters' size ÷ 1.24, the SVG's font-size) and on the same baseline for each anchor, so the
//! PNG and the SVG of a chart show their text in the same place.

use ab_glyph::{point, Font, FontRef, PxScale, ScaleFont};
use plotters_backend::text_anchor::{HPos, VPos};
use plotters_backend::{
    BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingBackend, DrawingErrorKind,
};
use std::sync::OnceLock;

/// The bundled font's file: the glyphs' outlines here, and plotters' registered font.
pub(super) const FONT_BYTES: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans.ttf");

/// Plotters' font size over the em size its SVG backend writes.
const SIZE_PER_EM: f64 = 1.24;

/// The baseline below a top-anchored text's position, in ems (the SVG backend's `dy`).
const TOP_BASELINE_EM: f32 = 0.76;

/// The bundled font, parsed once.
fn font() -> &'static FontRef<'static> {
    static FONT: OnceLock<FontRef<'static>> = OnceLock::new();
    FONT.get_or_init(|| FontRef::try_from_slice(FONT_BYTES).expect("the bundled font parses"))
}

/// A backend whose text is drawn from glyph outlines; everything else goes to `inner` as is.
pub(super) struct Glyphs<B> {
    inner: B,
}

impl<B: DrawingBackend> Glyphs<B> {
    /// Wraps `inner`.
    pub(super) fn new(inner: B) -> Glyphs<B> {
        Glyphs { inner }
    }
}

type Drawn<B> = Result<(), DrawingErrorKind<<B as DrawingBackend>::ErrorType>>;

impl<B: DrawingBackend> DrawingBackend for Glyphs<B> {
    type ErrorType = B::ErrorType;

    fn get_size(&self) -> (u32, u32) {
        self.inner.get_size()
    }

    fn ensure_prepared(&mut self) -> Drawn<B> {
        self.inner.ensure_prepared()
    }

    fn present(&mut self) -> Drawn<B> {
        self.inner.present()
    }

    fn draw_pixel(&mut self, point: BackendCoord, color: BackendColor) -> Drawn<B> {
        self.inner.draw_pixel(point, color)
    }

    fn draw_line<S: BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> Drawn<B> {
        self.inner.draw_line(from, to, style)
    }

    fn draw_rect<S: BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> Drawn<B> {
        self.inner.draw_rect(upper_left, bottom_right, style, fill)
    }

    fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> Drawn<B> {
        self.inner.draw_path(path, style)
    }

    fn draw_circle<S: BackendStyle>(
        &mut self,
        center: BackendCoord,
        radius: u32,
        style: &S,
        fill: bool,
    ) -> Drawn<B> {
        self.inner.draw_circle(center, radius, style, fill)
    }

    fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        vert: I,
        style: &S,
    ) -> Drawn<B> {
        self.inner.fill_polygon(vert, style)
    }

    fn blit_bitmap(&mut self, pos: BackendCoord, size: (u32, u32), src: &[u8]) -> Drawn<B> {
        self.inner.blit_bitmap(pos, size, src)
    }

    fn draw_text<S: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &S,
        pos: BackendCoord,
    ) -> Drawn<B> {
        let color = style.color();
        if color.alpha == 0.0 {
            return Ok(());
        }
        let font = font();
        let em = (style.size() / SIZE_PER_EM) as f32;
        let upem = font.units_per_em().unwrap_or(2048.0);
        let scale = PxScale::from(em * font.height_unscaled() / upem);
        let scaled = font.as_scaled(scale);
        // Pen positions first: the anchor needs the whole width.
        let mut pens = Vec::with_capacity(text.len());
        let mut pen = 0.0f32;
        let mut prev = None;
        for c in text.chars() {
            let id = scaled.glyph_id(c);
            if let Some(p) = prev {
                pen += scaled.kern(p, id);
            }
            pens.push((id, pen));
            pen += scaled.h_advance(id);
            prev = Some(id);
        }
        let dx = match style.anchor().h_pos {
            HPos::Left => 0.0,
            HPos::Center => -pen / 2.0,
            HPos::Right => -pen,
        };
        // The SVG backend's dy: 0.76em below a top anchor, half an x-height off a centre or
        // bottom one.
        let half_ex = x_height(font, scale) / 2.0;
        let baseline = match style.anchor().v_pos {
            VPos::Top => TOP_BASELINE_EM * em,
            VPos::Center => half_ex,
            VPos::Bottom => -half_ex,
        };
        let transform = style.transform();
        let (w, h) = self.get_size();
        for (id, x) in pens {
            let glyph = id.with_scale_and_position(scale, point(x + dx, baseline));
            let Some(outline) = font.outline_glyph(glyph) else {
                continue;
            };
            let bounds = outline.px_bounds();
            let mut coverage = Vec::new();
            outline.draw(|gx, gy, c| coverage.push((gx, gy, c)));
            for (gx, gy, c) in coverage {
                let (ox, oy) = (
                    bounds.min.x as i32 + gx as i32,
                    bounds.min.y as i32 + gy as i32,
                );
                let (tx, ty) = transform.transform(ox, oy);
                let (px, py) = (pos.0 + tx, pos.1 + ty);
                if c > 0.0 && px >= 0 && py >= 0 && px < w as i32 && py < h as i32 {
                    let mixed = BackendColor {
                        alpha: color.alpha * c.min(1.0) as f64,
                        rgb: color.rgb,
                    };
                    self.inner.draw_pixel((px, py), mixed)?;
                }
            }
        }
        Ok(())
    }
}

/// The x-height of `font` at `scale`: the height of the `x` glyph's ink.
fn x_height(font: &FontRef, scale: PxScale) -> f32 {
    let glyph = font.glyph_id('x').with_scale(scale);
    font.outline_glyph(glyph)
        .map_or(scale.y * 0.45, |o| -o.px_bounds().min.y)
}

#[cfg(test)]
mod tests {
    use super::*;
    use plotters::prelude::*;

    /// The widest run of blank columns between the first and the last inked column of `text`
    /// drawn at `size` on a white bitmap.
    fn widest_gap(text: &str, size: f64) -> usize {
        let (w, h) = (200u32, 40u32);
        let mut buf = vec![255u8; (w * h * 3) as usize];
        {
            let mut backend = Glyphs::new(BitMapBackend::with_buffer(&mut buf, (w, h)));
            let style = TextStyle::from(("sans-serif", size).into_font()).color(&BLACK);
            backend.draw_text(text, &style, (4, 4)).unwrap();
            backend.present().unwrap();
        }
        let inked: Vec<bool> = (0..w as usize)
            .map(|x| (0..h as usize).any(|y| buf[(y * w as usize + x) * 3] < 128))
            .collect();
        let first = inked.iter().position(|&i| i).expect("some ink");
        let last = inked.iter().rposition(|&i| i).unwrap();
        inked[first..=last]
            .split(|&i| i)
            .map(<[bool]>::len)
            .max()
            .unwrap_or(0)
    }

    /// The widest blank between two neighbouring glyphs' ink that the font itself leaves in
    /// `text` (right bearing plus the next left bearing), in pixels at `size`.
    fn font_gap(text: &str, size: f64) -> f32 {
        let font = font();
        let em = (size / SIZE_PER_EM) as f32;
        let scale = PxScale::from(em * font.height_unscaled() / font.units_per_em().unwrap());
        let scaled = font.as_scaled(scale);
        let chars: Vec<char> = text.chars().collect();
        chars
            .windows(2)
            .map(|pair| {
                let (a, b) = (scaled.glyph_id(pair[0]), scaled.glyph_id(pair[1]));
                let ink = |id: ab_glyph::GlyphId| {
                    font.outline_glyph(id.with_scale(scale))
                        .unwrap()
                        .px_bounds()
                };
                scaled.h_advance(a) - ink(a).max.x + ink(b).min.x + scaled.kern(a, b)
            })
            .fold(0.0, f32::max)
    }

    #[test]
    fn words_have_no_gaps_the_font_does_not_have() {
        for text in ["median", "40×40", "workload", "mm"] {
            let widest = widest_gap(text, 17.0);
            let allowed = font_gap(text, 17.0).ceil() as usize + 1;
            assert!(
                widest <= allowed,
                "{text}: a {widest} px gap, the font's widest is {allowed}"
            );
        }
    }
}
