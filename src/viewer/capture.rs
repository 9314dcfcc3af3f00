//! Reading a window's pixels back from the X server: what is on screen, for
//! the `capture` script step that the window test compares with an offscreen
//! render.

use winit::raw_window_handle::RawWindowHandle;
use x11rb::connection::Connection;
use x11rb::protocol::xproto::{ConnectionExt, ImageFormat};

/// The window's `width` x `height` pixels as 8-bit RGB, row 0 at the top,
/// read with `GetImage` over a new connection to `$DISPLAY`. Only for X11
/// windows on a 24- or 32-bit TrueColor visual with 32 bits per pixel.
pub fn capture_window(window: RawWindowHandle, (width, height): (u32, u32)) -> Result<Vec<u8>, String> {
    let id = match window {
        RawWindowHandle::Xlib(h) => h.window as u32,
        RawWindowHandle::Xcb(h) => h.window.get(),
        other => return Err(format!("window capture needs an X11 window, not {other:?}")),
    };
    let (conn, _) = x11rb::connect(None).map_err(|e| format!("cannot connect to the X server: {e}"))?;
    let w = u16::try_from(width).map_err(|_| "window too wide".to_string())?;
    let h = u16::try_from(height).map_err(|_| "window too tall".to_string())?;
    let reply = conn
        .get_image(ImageFormat::Z_PIXMAP, id, 0, 0, w, h, !0)
        .map_err(|e| format!("GetImage: {e}"))?
        .reply()
        .map_err(|e| format!("GetImage: {e}"))?;
    let format = conn.setup().pixmap_formats.iter().find(|f| f.depth == reply.depth).copied();
    let bpp = format.map_or(0, |f| f.bits_per_pixel);
    if bpp != 32 || reply.depth < 24 {
        return Err(format!(
            "window capture supports 32-bit pixels of depth 24 or 32 (got {bpp} bits, depth {})",
            reply.depth
        ));
    }
    let little_endian = conn.setup().image_byte_order == x11rb::protocol::xproto::ImageOrder::LSB_FIRST;
    let pad = format.map_or(32, |f| f.scanline_pad) as usize / 8;
    let stride = (width as usize * 4).div_ceil(pad) * pad;
    let mut rgb = Vec::with_capacity(width as usize * height as usize * 3);
    for row in reply.data.chunks(stride).take(height as usize) {
        for p in row[..width as usize * 4].chunks_exact(4) {
            // Pixel value 0x00RRGGBB (the usual TrueColor masks).
            let v = if little_endian {
                u32::from_le_bytes([p[0], p[1], p[2], p[3]])
            } else {
                u32::from_be_bytes([p[0], p[1], p[2], p[3]])
            };
            rgb.extend([(v >> 16) as u8, (v >> 8) as u8, v as u8]);
        }
    }
    if rgb.len() != width as usize * height as usize * 3 {
        return Err("the X server sent fewer pixels than asked for".into());
    }
    Ok(rgb)
}
