//! Text for the tiny-skia painter: laid out and rasterised by epaint (egui's own fonts,
//! so the PNG's labels match the window's), then blended into the pixmap glyph by glyph.

use egui::epaint::text::{FontDefinitions, Fonts, TextOptions};
use egui::epaint::{Color32, FontId};
use tiny_skia::Pixmap;

use std::sync::Arc;

use egui::epaint::Galley;

use super::style::Rgba;

/// egui's default fonts and their glyph atlas. Making one costs some milliseconds:
/// keep it for the next picture.
pub(super) struct Glyphs {
    fonts: Fonts,
}

impl Glyphs {
    pub(super) fn new() -> Self {
        Glyphs {
            fonts: Fonts::new(TextOptions::default(), FontDefinitions::default()),
        }
    }

    /// One line of `text` at `size` pixels, laid out.
    pub(super) fn layout(&mut self, text: &str, size: f32) -> Arc<Galley> {
        self.fonts.with_pixels_per_point(1.0).layout_no_wrap(
            text.to_owned(),
            FontId::proportional(size),
            Color32::WHITE,
        )
    }

    /// Draws a laid-out line with its top-left corner at `[left, top]` (pixels).
    pub(super) fn draw(
        &mut self,
        pixmap: &mut Pixmap,
        galley: &Galley,
        [left, top]: [f32; 2],
        colour: Rgba,
    ) {
        let atlas = self.fonts.texture_atlas().image();
        let (aw, ah) = (atlas.size[0], atlas.size[1]);
        let (pw, ph) = (pixmap.width() as i64, pixmap.height() as i64);
        let pixels = pixmap.pixels_mut();
        for placed in &galley.rows {
            for g in &placed.row.glyphs {
                let uv = g.uv_rect;
                if uv.is_nothing() || g.is_color {
                    continue;
                }
                let x0 = (left + placed.pos.x + g.pos.x + uv.offset.x).round() as i64;
                let y0 = (top + placed.pos.y + g.pos.y + uv.offset.y).round() as i64;
                for ty in uv.min[1] as usize..(uv.max[1] as usize).min(ah) {
                    let y = y0 + (ty - uv.min[1] as usize) as i64;
                    if y < 0 || y >= ph {
                        continue;
                    }
                    for tx in uv.min[0] as usize..(uv.max[0] as usize).min(aw) {
                        let x = x0 + (tx - uv.min[0] as usize) as i64;
                        if x < 0 || x >= pw {
                            continue;
                        }
                        let coverage = atlas.pixels[ty * aw + tx].a();
                        if coverage == 0 {
                            continue;
                        }
                        let i = (y * pw + x) as usize;
                        pixels[i] = blend(pixels[i], colour, coverage);
                    }
                }
            }
        }
    }
}

/// `colour` at `coverage` (0-255) over a premultiplied pixel.
fn blend(
    dst: tiny_skia::PremultipliedColorU8,
    colour: Rgba,
    coverage: u8,
) -> tiny_skia::PremultipliedColorU8 {
    let [r, g, b, a] = colour.0;
    let sa = u32::from(a) * u32::from(coverage) / 255;
    let inv = 255 - sa;
    let out_a = (sa + u32::from(dst.alpha()) * inv / 255).min(255);
    // Premultiplied source over premultiplied destination; no channel above alpha.
    let over = |s: u8, d: u8| (u32::from(s) * sa / 255 + u32::from(d) * inv / 255).min(out_a) as u8;
    tiny_skia::PremultipliedColorU8::from_rgba(
        over(r, dst.red()),
        over(g, dst.green()),
        over(b, dst.blue()),
        out_a as u8,
    )
    .unwrap_or(dst)
}
