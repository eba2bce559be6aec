//! The real GL behind the interposer: functions looked up with
//! `dlsym(RTLD_NEXT, name)`, i.e. in the libraries loaded after this one
//! (the system's libGL).

use core::ffi::{CStr, c_void};
use std::sync::OnceLock;

/// A real GL function, looked up on first use.
pub(crate) struct RealFn {
    name: &'static CStr,
    ptr: OnceLock<usize>,
}

impl RealFn {
    pub(crate) const fn new(name: &'static CStr) -> Self {
        Self { name, ptr: OnceLock::new() }
    }

    /// The function's address, or `None` if no later library has it.
    pub(crate) fn get(&self) -> Option<*const c_void> {
        let p = *self.ptr.get_or_init(|| {
            // SAFETY: `name` is a NUL-terminated string; RTLD_NEXT asks the
            // dynamic linker for the next definition after this library.
            let p = unsafe { libc::dlsym(libc::RTLD_NEXT, self.name.as_ptr()) } as usize;
            if p != 0 || self.name.to_bytes().starts_with(b"glX") {
                return p;
            }
            // Extensions and newer entry points a libGL may not export:
            // ask GLX, as programs do.
            // SAFETY: a NUL-terminated name.
            unsafe { glXGetProcAddressARB(self.name.as_ptr().cast()) }.map_or(0, |f| f as usize)
        });
        (p != 0).then_some(p as *const c_void)
    }
}

/// Declares `pub(crate) unsafe fn name(args) -> ret` calling the real
/// function (doing nothing, returning the default, if it is missing).
macro_rules! real_fns {
    ($($name:ident($($a:ident: $t:ty),*) $(-> $r:ty)?;)*) => {
        $(
            #[allow(non_snake_case)]
            pub(crate) unsafe fn $name($($a: $t),*) $(-> $r)? {
                static REAL: RealFn = RealFn::new(
                    // SAFETY: the literal ends in its only NUL.
                    unsafe { CStr::from_bytes_with_nul_unchecked(concat!(stringify!($name), "\0").as_bytes()) },
                );
                match REAL.get() {
                    Some(p) => {
                        // SAFETY: the symbol of that name in the system's
                        // GL has this C signature (the GL specification's).
                        let f: unsafe extern "C" fn($($t),*) $(-> $r)? = unsafe { core::mem::transmute(p) };
                        // SAFETY: the caller passes arguments valid for it.
                        unsafe { f($($a),*) }
                    }
                    None => Default::default(),
                }
            }
        )*
    };
}

real_fns! {
    glPushAttrib(mask: u32);
    glPopAttrib();
    glPushClientAttrib(mask: u32);
    glPopClientAttrib();
    glMatrixMode(mode: u32);
    glPushMatrix();
    glPopMatrix();
    glLoadIdentity();
    glDisable(cap: u32);
    glPixelStorei(pname: u32, param: i32);
    glPixelZoom(x: f32, y: f32);
    glWindowPos2i(x: i32, y: i32);
    glDrawPixels(w: i32, h: i32, format: u32, ty: u32, data: *const c_void);
    glReadPixels(x: i32, y: i32, w: i32, h: i32, format: u32, ty: u32, data: *mut c_void);
    glReadBuffer(mode: u32);
    glGetBooleanv(pname: u32, data: *mut u8);
    glXSwapBuffers(dpy: *mut c_void, drawable: u64);
    glXGetProcAddress(name: *const u8) -> Option<unsafe extern "C" fn()>;
    glXGetProcAddressARB(name: *const u8) -> Option<unsafe extern "C" fn()>;
}
