//! host-sim's own drawing of the Foxglove layout's plot panels from a flight log
//! (docs/logs.md#layouts, Choice 383), without a browser (the README's picture is Foxglove's,
//! `scripts/viewer-screenshot.sh`).
//!
//!     cargo run --profile host -p host-sim --example layout_views -- \
//!         layouts/auv150.foxglove.json runs/x/circle-with.mcap docs/images/flight-views.png

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use host_sim::output::log::{read::read_flight, views};

fn main() -> Result<()> {
    let args: Vec<PathBuf> = std::env::args_os().skip(1).map(PathBuf::from).collect();
    let [layout, log, png] = args.as_slice() else {
        anyhow::bail!("usage: layout_views LAYOUT.foxglove.json LOG.mcap OUT.png");
    };
    let text = std::fs::read_to_string(layout).with_context(|| layout.display().to_string())?;
    let layout: serde_json::Value = serde_json::from_str(&text)?;
    let flight = read_flight(log)?;
    let name = log
        .file_stem()
        .map_or(String::new(), |s| s.to_string_lossy().into_owned());
    let title = format!("{name}: the layout's views, drawn by host-sim (not Foxglove)");
    let left_out = views::draw(&layout, &flight, &title, png)?;
    shrink(png)?;
    println!("{}", png.display());
    for t in left_out {
        println!("not drawn (no data in this log): {t}");
    }
    Ok(())
}

/// Rewrites the RGB PNG at `path` with a palette of its 256 most frequent colours (each other
/// colour, anti-aliasing's blends, as the nearest of them): the same picture in a third of the
/// bytes, small enough to keep in the repository.
fn shrink(path: &Path) -> Result<()> {
    let decoder = png::Decoder::new(std::fs::File::open(path)?);
    let mut reader = decoder.read_info()?;
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf)?;
    anyhow::ensure!(
        info.color_type == png::ColorType::Rgb && info.bit_depth == png::BitDepth::Eight,
        "{} is not an 8-bit RGB PNG",
        path.display()
    );
    let pixels: Vec<[u8; 3]> = buf[..info.buffer_size()]
        .chunks_exact(3)
        .map(|p| [p[0], p[1], p[2]])
        .collect();
    let mut counts: HashMap<[u8; 3], usize> = HashMap::new();
    for p in &pixels {
        *counts.entry(*p).or_default() += 1;
    }
    let mut by_count: Vec<([u8; 3], usize)> = counts.into_iter().collect();
    by_count.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    let palette: Vec<[u8; 3]> = by_count.iter().take(256).map(|c| c.0).collect();
    let mut index: HashMap<[u8; 3], u8> = HashMap::new();
    let nearest = |c: [u8; 3]| -> u8 {
        let d = |p: &[u8; 3]| -> i32 {
            (0..3)
                .map(|i| (i32::from(p[i]) - i32::from(c[i])).pow(2))
                .sum()
        };
        let best = (0..palette.len())
            .min_by_key(|&i| d(&palette[i]))
            .unwrap_or(0);
        u8::try_from(best).unwrap_or(0)
    };
    let indexed: Vec<u8> = pixels
        .iter()
        .map(|p| *index.entry(*p).or_insert_with(|| nearest(*p)))
        .collect();
    let file = std::io::BufWriter::new(std::fs::File::create(path)?);
    let mut encoder = png::Encoder::new(file, info.width, info.height);
    encoder.set_color(png::ColorType::Indexed);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_palette(palette.concat());
    encoder.set_compression(png::Compression::Best);
    encoder.write_header()?.write_image_data(&indexed)?;
    Ok(())
}
