//! The final stock as a height map image: one pixel per voxel column, 16-bit grey, the
//! top of the column's highest material interval scaled from the grid's bottom face (0,
//! black, or an empty column) to its top face (65535, white). North up: the image's first
//! row is the grid's largest y.

use super::stock::Stock;
use anyhow::{Context, Result};
use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

/// Writes `stock`'s height map to `path` as PNG.
pub fn write_png(stock: &Stock, path: &Path) -> Result<()> {
    let [nx, ny, nz] = stock.dims();
    let name = path.display().to_string();
    let f = File::create(path).with_context(|| format!("cannot create {name}"))?;
    let mut enc = png::Encoder::new(BufWriter::new(f), nx as u32, ny as u32);
    enc.set_color(png::ColorType::Grayscale);
    enc.set_depth(png::BitDepth::Sixteen);
    let mut w = enc
        .write_header()
        .with_context(|| format!("cannot write {name}"))?;
    let mut data = Vec::with_capacity(nx * ny * 2);
    for iy in (0..ny).rev() {
        for ix in 0..nx {
            let top = u32::from(stock.top(ix, iy));
            let v = (top * 65535 / nz as u32) as u16;
            data.extend_from_slice(&v.to_be_bytes());
        }
    }
    w.write_image_data(&data)
        .with_context(|| format!("cannot write {name}"))?;
    w.finish().with_context(|| format!("cannot write {name}"))?;
    Ok(())
}
