//! A growable, reusable scratch buffer for faer's `MemStack`-based kernels.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};

/// Keeps one allocation and regrows it only when a kernel asks for more, so repeated
/// factorizations and solves of the same size allocate nothing.
pub(crate) struct Scratch {
    buffer: MemBuffer,
    req: StackReq,
}

impl Scratch {
    pub(crate) fn new() -> Self {
        Self {
            buffer: MemBuffer::new(StackReq::empty()),
            req: StackReq::empty(),
        }
    }

    /// A stack with room for at least `req`.
    pub(crate) fn stack(&mut self, req: StackReq) -> &mut MemStack {
        if req.size_bytes() > self.req.size_bytes() || req.align_bytes() > self.req.align_bytes() {
            self.req = self.req.or(req);
            self.buffer = MemBuffer::new(self.req);
        }
        MemStack::new(&mut self.buffer)
    }
}

impl std::fmt::Debug for Scratch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Scratch")
            .field("bytes", &self.req.size_bytes())
            .finish()
    }
}
