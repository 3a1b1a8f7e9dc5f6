//! Image output: a frame as PNG bytes (written through [`AtomicFile`](crate::atomic_file::AtomicFile)).

/// `img` encoded as PNG.
pub fn png_bytes(img: &image::RgbImage) -> Vec<u8> {
    let mut bytes = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut bytes), image::ImageFormat::Png)
        .expect("PNG encoding into memory cannot fail");
    bytes
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn png_bytes_decode_to_the_same_image() {
        let img = image::RgbImage::from_fn(3, 2, |x, y| image::Rgb([x as u8 * 80, y as u8 * 100, 7]));
        let back = image::load_from_memory(&png_bytes(&img)).unwrap().to_rgb8();
        assert_eq!(back, img);
    }
}
