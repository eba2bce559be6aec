//! Passes put together as GL's depth buffer puts draws together, without
//! any GL: depth order within the depth test, draw order without it or
//! after a depth clear, GL's raster kept where an overlay wins.

use rt_core::glam::Vec4;
use rt_gl::{
    composite::{Content, Layer, composite, keeps_raster},
    render::Image,
};

const INF: f32 = f32::INFINITY;

fn traced(viewport: [i32; 4], colors: &[[u8; 4]], depth: Vec<f32>) -> Content {
    let image = Image {
        width: viewport[2] as u32,
        height: viewport[3] as u32,
        rgba: colors.iter().flatten().copied().collect(),
    };
    Content::Traced { image, depth }
}

fn layer(viewport: [i32; 4], depth_test: bool, depth_cleared: bool, content: Content) -> Layer {
    let background = Vec4::new(0.0, 0.0, 1.0, 1.0);
    Layer { viewport, depth_test, depth_cleared, background, content }
}

/// One row of seven pixels through four passes: a traced one, an overlay
/// drawn with the depth test (behind at one pixel, in front at the
/// next), a traced pass after a depth clear, and an overlay without the
/// depth test at the last pixel.
#[test]
fn passes_composite_as_the_depth_buffer_orders_them() {
    let red = [200, 0, 0, 255];
    let green = [0, 200, 0, 255];
    let row = [0, 0, 7, 1];
    let first = traced(row, &[red; 7], vec![0.5, 0.5, INF, INF, INF, 0.5, 0.5]);
    let overlay = Content::Raster { depth: vec![0.7, 0.3, INF, INF, INF, INF, INF] };
    // Far behind the first pass, but drawn after a depth clear.
    let after_clear = traced([4, 0, 2, 1], &[green; 2], vec![0.99, INF]);
    let on_top = Content::Raster { depth: vec![INF, INF, INF, INF, INF, INF, 0.9] };
    let out = composite(
        row,
        &[
            layer(row, true, false, first),
            layer(row, true, false, overlay),
            layer([4, 0, 2, 1], true, true, after_clear),
            layer(row, false, false, on_top),
        ],
        None,
    );
    let px: Vec<[u8; 4]> = out.rgba.chunks_exact(4).map(|p| [p[0], p[1], p[2], p[3]]).collect();
    // 0: the traced pass is nearer than the overlay; 1: the overlay is
    // nearer (GL's pixel: alpha 0); 2: the overlay's uncovered neighbour
    // (coverage widened by a pixel for what rays miss); 3: nothing, the
    // traced pass's background; 4: the pass after the depth clear; 5:
    // the first pass, uncovered by the later one, and 6: the overlay
    // drawn without the depth test, whose coverage also widens onto 5.
    assert_eq!(px[0], [200, 0, 0, 255]);
    assert_eq!(px[1][3], 0);
    assert_eq!(px[2][3], 0);
    assert_eq!(px[3], [0, 0, 255, 255]);
    assert_eq!(px[4], [0, 200, 0, 255]);
    assert_eq!(px[5][3], 0);
    assert_eq!(px[6][3], 0);
    assert!(keeps_raster(&out));
}

/// A pass that could not be traced keeps its whole viewport as GL drew
/// it; outside every traced viewport GL's pixels stay too.
#[test]
fn untraced_passes_and_pixels_outside_traced_viewports_keep_the_raster() {
    let left = [0, 0, 2, 1];
    let red = [200, 0, 0, 255];
    let out = composite(
        [0, 0, 4, 1],
        &[
            layer(left, true, false, traced(left, &[red; 2], vec![0.5, INF])),
            layer([1, 0, 1, 1], true, false, Content::Untraced),
        ],
        None,
    );
    let alpha: Vec<u8> = out.rgba.chunks_exact(4).map(|p| p[3]).collect();
    assert_eq!(alpha, [255, 0, 0, 0]);
    assert_eq!(&out.rgba[..3], &red[..3]);
}

/// A pass seen through blended surfaces only (premultiplied colour,
/// opacity below 1) goes over what earlier passes show: an earlier traced
/// colour, GL's own pixel where an overlay was kept (read back), or the
/// background where nothing was drawn.
#[test]
fn translucent_passes_blend_over_what_is_below() {
    // Pixels 1 and 3 are left between (an overlay's coverage widens onto
    // its neighbours).
    let row = [0, 0, 5, 1];
    let red = [200, 0, 0, 255];
    // Half-opaque blue, premultiplied: (0, 0, 100) at alpha 128.
    let glass = [0, 0, 100, 128];
    let first = traced(row, &[red, [0; 4], [0; 4], [0; 4], [0; 4]], vec![0.8, INF, INF, INF, INF]);
    let kept = Content::Raster { depth: vec![INF, INF, 0.9, INF, INF] };
    let over = traced(row, &[glass; 5], vec![0.5; 5]);
    let gl = [[9, 9, 9, 255], [9; 4], [0, 240, 0, 255], [9; 4], [9; 4]];
    let raster = Image { width: 5, height: 1, rgba: gl.concat() };
    let layers = [
        layer(row, true, false, first),
        layer(row, false, false, kept),
        layer(row, true, false, over),
    ];
    assert!(rt_gl::composite::needs_raster(&layers));
    let out = composite(row, &layers, Some(&raster));
    let px: Vec<&[u8]> = out.rgba.chunks_exact(4).collect();
    let k = 1.0 - 128.0 / 255.0;
    let mix = |below: f64, own: f64| (own + k * below).round() as u8;
    // Over the red pass, over GL's green pixel, over the blue background.
    assert_eq!(px[0], [mix(200.0, 0.0), 0, mix(0.0, 100.0), 255]);
    assert_eq!(px[2], [0, mix(240.0, 0.0), mix(0.0, 100.0), 255]);
    assert_eq!(px[4], [0, 0, mix(255.0, 100.0), 255]);
}
