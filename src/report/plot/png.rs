//! A heat map's cells as one PNG, embedded in the SVG as a base64 `data:` URI (one `<image>`
//! instead of one `<rect>` per cell: a 250×250-cell spectrogram drawn as rectangles is ≈ 5 MB of
//! SVG; as a PNG it is tens of kB). Encoding by the `png` crate (8-bit RGB), base64 by the
//! `base64` crate (RFC 4648 §4, standard alphabet with padding).

use base64::Engine as _;

/// PNG bytes of a `width × height` RGB image, `rgb` row-major from the top, 3 bytes per pixel.
/// Returns `None` if `rgb` has the wrong length, a dimension is 0, or the encoder fails.
pub(crate) fn encode_rgb(width: u32, height: u32, rgb: &[u8]) -> Option<Vec<u8>> {
    if width == 0 || height == 0 || rgb.len() != width as usize * height as usize * 3 {
        return None;
    }
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, width, height);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let mut w = enc.write_header().ok()?;
    w.write_image_data(rgb).ok()?;
    w.finish().ok()?;
    Some(out)
}

/// `data:image/png;base64,...` URI of PNG bytes.
pub(crate) fn data_uri(png: &[u8]) -> String {
    format!(
        "data:image/png;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(png)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn png_round_trips_through_the_decoder() {
        let (w, h) = (3u32, 2u32);
        let rgb: Vec<u8> = (0..18).map(|i| i * 13).collect();
        let bytes = encode_rgb(w, h, &rgb).unwrap();
        // PNG signature (PNG spec 2nd ed. §5.2).
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
        let dec = png::Decoder::new(std::io::Cursor::new(&bytes));
        let mut reader = dec.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height), (w, h));
        assert_eq!(info.color_type, png::ColorType::Rgb);
        assert_eq!(info.bit_depth, png::BitDepth::Eight);
        assert_eq!(&buf[..info.buffer_size()], &rgb[..]);
        assert!(encode_rgb(0, 1, &[]).is_none());
        assert!(encode_rgb(2, 2, &[0; 5]).is_none());
    }

    #[test]
    fn data_uri_is_standard_base64() {
        // RFC 4648 §10 test vector "foobar" -> "Zm9vYmFy", and one with padding.
        assert_eq!(data_uri(b"foobar"), "data:image/png;base64,Zm9vYmFy");
        assert_eq!(data_uri(b"fo"), "data:image/png;base64,Zm8=");
    }
}
