//! A growable, reusable scratch buffer for faer's `MemStack`-based kernels.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};

use super::LinearSolveError;

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

    /// A stack with room for at least `req`; an allocation failure is
    /// [`LinearSolveError::OutOfMemory`], not an abort.
    pub(crate) fn stack(&mut self, req: StackReq) -> Result<&mut MemStack, LinearSolveError> {
        if req.size_bytes() > self.req.size_bytes() || req.align_bytes() > self.req.align_bytes() {
            let grown = self.req.or(req);
            self.buffer = MemBuffer::try_new(grown).map_err(|_| LinearSolveError::OutOfMemory {
                during: "allocating the scratch memory of a factorization",
            })?;
            self.req = grown;
        }
        Ok(MemStack::new(&mut self.buffer))
    }
}

impl std::fmt::Debug for Scratch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Scratch")
            .field("bytes", &self.req.size_bytes())
            .finish()
    }
}
