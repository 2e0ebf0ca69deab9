//! Property tests of the foundation types: buffers, pixel indexing, channel split and
//! join, kinds, borrowed views and crops, and the border rule every filter and demosaicer
//! relies on.

use polar_image::{
    Border, Gray, Image, ImageError, ImageView, Plain, PolarizerStack, StokesImage, is_mosaic_size,
    kind,
};
use proptest::prelude::*;

fn image3() -> impl Strategy<Value = Image<i32, 3>> {
    (1usize..9, 1usize..9).prop_flat_map(|(w, h)| {
        proptest::collection::vec(-1000i32..1000, w * h * 3)
            .prop_map(move |v| Image::from_vec(w, h, v).unwrap())
    })
}

proptest! {
    #[test]
    fn buffer_length_must_be_width_times_height_times_channels(w in 0usize..20, h in 0usize..20, extra in 1usize..5) {
        prop_assert!(Image::<u8, 2>::from_vec(w, h, vec![0; w * h * 2]).is_ok());
        let bad = Image::<u8, 2>::from_vec(w, h, vec![0; w * h * 2 + extra]);
        let is_buffer_size_error = matches!(bad, Err(ImageError::BufferSize { .. }));
        prop_assert!(is_buffer_size_error);
    }

    #[test]
    fn pixel_x_y_is_row_major(img in image3()) {
        let (w, h) = img.size();
        for y in 0..h {
            for x in 0..w {
                let k = (y * w + x) * 3;
                prop_assert_eq!(img.pixel(x, y), &[img.as_slice()[k], img.as_slice()[k + 1], img.as_slice()[k + 2]]);
            }
        }
    }

    #[test]
    fn channels_split_and_join_to_the_same_image(img in image3()) {
        let (a, b, c) = (img.channel(0), img.channel(1), img.channel(2));
        prop_assert_eq!(Image::from_channels([&a, &b, &c]).unwrap(), img.clone());
        prop_assert_eq!(img.clone().into_vec().len(), img.width() * img.height() * 3);
    }

    #[test]
    fn channels_of_different_sizes_do_not_join(w in 1usize..6, h in 1usize..6) {
        let a: Gray<u8> = Gray::new(w, h);
        let b: Gray<u8> = Gray::new(w + 1, h);
        prop_assert!(Image::<u8, 2>::from_channels([&a, &b]).is_err());
    }

    #[test]
    fn border_index_stays_inside_and_is_identity_inside(i in -50isize..50, n in 1usize..12) {
        for b in [Border::Reflect101, Border::Reflect, Border::Replicate] {
            let j = b.index(i, n);
            prop_assert!(j < n);
            if (0..n as isize).contains(&i) {
                prop_assert_eq!(j as isize, i);
            }
        }
    }

    #[test]
    fn reflect_101_keeps_the_parity_of_the_offset(i in -50isize..50, half in 1usize..8) {
        // On an even-sized mosaic row, reflect-101 keeps every sample's polarizer (parity).
        let n = 2 * half;
        prop_assert_eq!(Border::Reflect101.index(i, n) % 2, i.rem_euclid(2) as usize);
    }

    #[test]
    fn mosaic_size_is_whole_super_pixels(w in 0usize..40, h in 0usize..40) {
        prop_assert_eq!(is_mosaic_size(w, h), w >= 2 && h >= 2 && w % 2 == 0 && h % 2 == 0);
    }
}

/// An image of 1..9 × 1..9 pixels with two channels, and a rectangle inside it.
fn image_and_rect() -> impl Strategy<Value = (Image<i32, 2>, (usize, usize, usize, usize))> {
    (1usize..9, 1usize..9).prop_flat_map(|(w, h)| {
        let img = proptest::collection::vec(-1000i32..1000, w * h * 2)
            .prop_map(move |v| Image::from_vec(w, h, v).unwrap());
        let rect =
            (0..=w, 0..=h).prop_flat_map(move |(x, y)| (Just(x), Just(y), 0..=w - x, 0..=h - y));
        (img, rect)
    })
}

proptest! {
    #[test]
    fn a_view_of_an_image_copies_back_to_the_same_image(img in image3()) {
        let view = img.view();
        prop_assert_eq!(view.size(), img.size());
        prop_assert_eq!(view.stride(), img.width());
        let back: Image<i32, 3> = view.to_image();
        prop_assert_eq!(back, img.clone());
        for (y, row) in view.rows().enumerate() {
            let w = img.width() * 3;
            prop_assert_eq!(row, &img.as_slice()[y * w..(y + 1) * w]);
        }
    }

    #[test]
    fn a_crop_reads_the_pixels_of_its_rectangle((img, (x0, y0, w, h)) in image_and_rect()) {
        let crop = img.view().crop(x0, y0, w, h).unwrap();
        prop_assert_eq!(crop.size(), (w, h));
        for y in 0..h {
            for x in 0..w {
                prop_assert_eq!(crop.pixel(x, y), img.pixel(x0 + x, y0 + y));
            }
        }
        // A crop of a crop is the crop of the offsets added.
        if w > 0 && h > 0 {
            let inner = crop.crop(w / 2, h / 2, w - w / 2, h - h / 2).unwrap();
            let direct = img.view().crop(x0 + w / 2, y0 + h / 2, w - w / 2, h - h / 2).unwrap();
            prop_assert_eq!(inner.to_image::<Plain>(), direct.to_image::<Plain>());
        }
    }

    #[test]
    fn a_crop_reaching_outside_is_refused(w in 1usize..8, h in 1usize..8, x in 0usize..10, y in 0usize..10, cw in 0usize..10, ch in 0usize..10) {
        let img: Image<u8, 2> = Image::new(w, h);
        let inside = x + cw <= w && y + ch <= h;
        let crop = img.view().crop(x, y, cw, ch);
        prop_assert_eq!(crop.is_ok(), inside);
        if !inside {
            let is_crop_error = matches!(crop, Err(ImageError::CropBounds { .. }));
            prop_assert!(is_crop_error);
        }
    }

    #[test]
    fn a_view_needs_its_last_row_inside_the_buffer(w in 0usize..6, h in 0usize..6, pad in 0usize..4, len in 0usize..80) {
        let stride = w + pad;
        let buf = vec![0u16; len];
        let needed = if h == 0 { 0 } else { ((h - 1) * stride + w) * 3 };
        let view = ImageView::<u16, 3>::new(&buf, w, h, stride);
        prop_assert_eq!(view.is_ok(), needed <= len);
        // A stride shorter than the width is refused whatever the buffer.
        if w > 0 {
            let short = ImageView::<u16, 3>::new(&buf, w, h, w - 1);
            let is_view_error = matches!(short, Err(ImageError::ViewBounds { .. }));
            prop_assert!(is_view_error);
        }
    }

    #[test]
    fn rows_of_a_strided_view_skip_the_padding(w in 1usize..6, h in 1usize..6, pad in 0usize..4) {
        // Every sample holds its own index, so each row must start at y * stride.
        let stride = w + pad;
        let buf: Vec<usize> = (0..h * stride).collect();
        let view = ImageView::<usize, 1>::new(&buf, w, h, stride).unwrap();
        for y in 0..h {
            let want: Vec<usize> = (y * stride..y * stride + w).collect();
            prop_assert_eq!(view.row(y), &want[..]);
            prop_assert_eq!(view.at(w - 1, y), y * stride + w - 1);
        }
        let copy: Gray<usize> = view.to_image();
        prop_assert_eq!(copy.size(), (w, h));
    }

    #[test]
    fn changing_the_kind_keeps_every_sample(img in image3()) {
        let stokes: Image<i32, 3, kind::LinearStokes> = img.clone().into_kind();
        prop_assert_eq!(stokes.as_slice(), img.as_slice());
        prop_assert_eq!(stokes.size(), img.size());
        let back: Image<i32, 3> = stokes.into_kind();
        prop_assert_eq!(back, img);
    }

    #[test]
    fn channels_of_any_kind_join_into_any_kind(data in proptest::collection::vec(-9.0f32..9.0, 4 * 6)) {
        let stokes = StokesImage::from_vec(3, 2, data).unwrap();
        let planes = [0, 1, 2, 3].map(|c| stokes.channel(c));
        let stack = PolarizerStack::from_channels([&planes[0], &planes[1], &planes[2], &planes[3]]).unwrap();
        prop_assert_eq!(stack.as_slice(), stokes.as_slice());
    }
}

#[test]
#[should_panic(expected = "row 2 of a view 2 high")]
fn a_row_below_a_crop_is_not_read_from_the_image_under_it() {
    let img: Gray<u8> = Gray::new(4, 4);
    let crop = img.view().crop(0, 0, 4, 2).unwrap();
    let _ = crop.row(2);
}

#[test]
#[should_panic(expected = "column 2 outside a view 2 wide")]
fn a_pixel_right_of_a_crop_is_not_read_from_the_image_under_it() {
    let img: Gray<u8> = Gray::new(4, 4);
    let crop = img.view().crop(0, 0, 2, 2).unwrap();
    let _ = crop.at(2, 0);
}

#[test]
#[should_panic(expected = "index out of bounds")]
fn a_pixel_below_a_crop_is_not_read_from_the_image_under_it() {
    let img: Gray<u8> = Gray::new(4, 4);
    let crop = img.view().crop(1, 1, 2, 2).unwrap();
    let _ = crop.at(0, 2);
}
