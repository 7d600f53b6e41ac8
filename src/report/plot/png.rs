//! A minimal PNG encoder (8-bit RGB, no filtering, zlib via `flate2`) and base64, for embedding a
//! heat map into an SVG as one `<image>` instead of one `<rect>` per cell (a 250×250-cell
//! spectrogram drawn as rectangles is ≈ 5 MB of SVG; as a PNG it is tens of kB).
//!
//! Format: PNG specification (W3C, 2nd ed.), §5 (signature, chunk layout, CRC-32 over type+data),
//! §11.2.2 (IHDR), §7.3 + §9 (filter type 0 per scanline), §10 (zlib stream).

use std::io::Write;

use flate2::Crc;
use flate2::write::ZlibEncoder;

fn chunk(out: &mut Vec<u8>, kind: &[u8; 4], data: &[u8]) {
    out.extend_from_slice(&(data.len() as u32).to_be_bytes());
    out.extend_from_slice(kind);
    out.extend_from_slice(data);
    let mut crc = Crc::new();
    crc.update(kind);
    crc.update(data);
    out.extend_from_slice(&crc.sum().to_be_bytes());
}

/// PNG bytes of a `width × height` RGB image, `rgb` row-major from the top, 3 bytes per pixel.
/// Returns `None` if `rgb` has the wrong length or a dimension is 0.
pub(crate) fn encode_rgb(width: u32, height: u32, rgb: &[u8]) -> Option<Vec<u8>> {
    let row = width as usize * 3;
    if width == 0 || height == 0 || rgb.len() != row * height as usize {
        return None;
    }
    let mut z = ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    for line in rgb.chunks(row) {
        z.write_all(&[0]).ok()?; // filter type 0 (None)
        z.write_all(line).ok()?;
    }
    let idat = z.finish().ok()?;
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut ihdr = Vec::with_capacity(13);
    ihdr.extend_from_slice(&width.to_be_bytes());
    ihdr.extend_from_slice(&height.to_be_bytes());
    ihdr.extend_from_slice(&[8, 2, 0, 0, 0]); // 8-bit, truecolour, deflate, filter 0, no interlace
    chunk(&mut out, b"IHDR", &ihdr);
    chunk(&mut out, b"IDAT", &idat);
    chunk(&mut out, b"IEND", &[]);
    Some(out)
}

/// Standard base64 (RFC 4648 §4) with padding.
pub(crate) fn base64(data: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::with_capacity(data.len().div_ceil(3) * 4);
    for c in data.chunks(3) {
        let b = [c[0], *c.get(1).unwrap_or(&0), *c.get(2).unwrap_or(&0)];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for i in 0..4 {
            if i <= c.len() {
                s.push(A[(n >> (18 - 6 * i) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Read;

    #[test]
    fn base64_rfc4648_vectors() {
        // RFC 4648 §10 test vectors.
        for (i, o) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(i.as_bytes()), o);
        }
    }

    #[test]
    fn png_structure_and_payload() {
        let (w, h) = (3u32, 2u32);
        let rgb: Vec<u8> = (0..18).collect();
        let png = encode_rgb(w, h, &rgb).unwrap();
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
        assert_eq!(&png[12..16], b"IHDR");
        assert_eq!(u32::from_be_bytes(png[16..20].try_into().unwrap()), w);
        assert_eq!(u32::from_be_bytes(png[20..24].try_into().unwrap()), h);
        // CRC of IHDR: the well-known value for a 3×2 8-bit RGB header is checked by recomputing.
        let mut crc = Crc::new();
        crc.update(&png[12..29]);
        assert_eq!(
            crc.sum(),
            u32::from_be_bytes(png[29..33].try_into().unwrap())
        );
        // IDAT decompresses to filter byte + row, twice.
        let len = u32::from_be_bytes(png[33..37].try_into().unwrap()) as usize;
        assert_eq!(&png[37..41], b"IDAT");
        let mut raw = Vec::new();
        flate2::read::ZlibDecoder::new(&png[41..41 + len])
            .read_to_end(&mut raw)
            .unwrap();
        let mut want = vec![0u8];
        want.extend(0..9u8);
        want.push(0);
        want.extend(9..18u8);
        assert_eq!(raw, want);
        assert!(png.ends_with(&[0, 0, 0, 0, b'I', b'E', b'N', b'D', 0xAE, 0x42, 0x60, 0x82]));
        assert!(encode_rgb(0, 1, &[]).is_none());
        assert!(encode_rgb(2, 2, &[0; 5]).is_none());
    }
}
