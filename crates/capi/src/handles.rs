//! Live handles. A handle the host holds is a number, never a pointer to Rust memory: the
//! `TesseraContext*`/`TesseraSurface*` it sees is that number cast to a pointer and is never
//! dereferenced. So a null, forged, destroyed or twice-destroyed handle is looked up, found
//! missing and answered with a code; it can never reach freed memory.
//!
//! Numbers come from one 64-bit counter shared by every kind (contexts, surfaces, limit
//! evaluators) and are never reused, so a destroyed handle stays distinguishable from one never
//! issued, and a surface passed where a context is expected is not mistaken for one.
use crate::status::{Error, Result, TesseraStatus};
use std::collections::HashMap;
use std::sync::{Arc, Mutex, MutexGuard};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Kind {
    Context,
    Surface,
    Evaluator,
}

impl Kind {
    fn name(self) -> &'static str {
        match self {
            Kind::Context => "context",
            Kind::Surface => "surface",
            Kind::Evaluator => "limit evaluator",
        }
    }
}

/// Every handle issued: its kind and whether it is live. Destroyed entries stay (a few bytes
/// each) so double destroy and use after destroy are told apart from a forged handle.
pub(crate) struct HandleTable<C, S, E> {
    next: u64,
    issued: HashMap<u64, Kind>,
    contexts: HashMap<u64, Arc<Mutex<C>>>,
    /// Each live surface with the context it was created on.
    surfaces: HashMap<u64, (u64, Arc<Mutex<S>>)>,
    /// Limit evaluators: immutable, so shared without a lock (any number of threads at once).
    evaluators: HashMap<u64, Arc<E>>,
}

impl<C, S, E> Default for HandleTable<C, S, E> {
    fn default() -> Self {
        Self {
            // 0 is the null handle; start high enough that small forged integers are unissued.
            next: 0x1000,
            issued: HashMap::new(),
            contexts: HashMap::new(),
            surfaces: HashMap::new(),
            evaluators: HashMap::new(),
        }
    }
}

impl<C, S, E> HandleTable<C, S, E> {
    fn issue(&mut self, kind: Kind) -> u64 {
        // Ids step by 16 so that the pointer a host sees is aligned like a real one.
        let id = self.next;
        self.next += 16;
        self.issued.insert(id, kind);
        id
    }

    pub fn add_context(&mut self, c: C) -> u64 {
        let id = self.issue(Kind::Context);
        self.contexts.insert(id, Arc::new(Mutex::new(c)));
        id
    }

    pub fn add_surface(&mut self, context: u64, s: S) -> u64 {
        let id = self.issue(Kind::Surface);
        self.surfaces.insert(id, (context, Arc::new(Mutex::new(s))));
        id
    }

    pub fn add_evaluator(&mut self, e: E) -> u64 {
        let id = self.issue(Kind::Evaluator);
        self.evaluators.insert(id, Arc::new(e));
        id
    }

    pub fn evaluator(&self, id: u64) -> Result<Arc<E>> {
        self.evaluators
            .get(&id)
            .cloned()
            .ok_or_else(|| self.missing(id, Kind::Evaluator))
    }

    pub fn remove_evaluator(&mut self, id: u64) -> Result<Arc<E>> {
        match self.evaluators.remove(&id) {
            Some(e) => Ok(e),
            None => Err(self.missing(id, Kind::Evaluator)),
        }
    }

    fn missing(&self, id: u64, want: Kind) -> Error {
        if id == 0 {
            return Error::new(
                TesseraStatus::NullHandle,
                format!("the {} handle is null", want.name()),
            );
        }
        match self.issued.get(&id) {
            Some(k) if *k == want => Error::new(
                TesseraStatus::DestroyedHandle,
                format!(
                    "{} handle {id:#x} was destroyed (double destroy or use after destroy)",
                    want.name()
                ),
            ),
            Some(k) => Error::new(
                TesseraStatus::InvalidHandle,
                format!(
                    "handle {id:#x} is a {} handle, not a {} handle",
                    k.name(),
                    want.name()
                ),
            ),
            None => Error::new(
                TesseraStatus::InvalidHandle,
                format!(
                    "{id:#x} is not a {} handle this library issued",
                    want.name()
                ),
            ),
        }
    }

    pub fn context(&self, id: u64) -> Result<Arc<Mutex<C>>> {
        self.contexts
            .get(&id)
            .cloned()
            .ok_or_else(|| self.missing(id, Kind::Context))
    }

    /// The surface `id` and the context it belongs to.
    pub fn surface(&self, id: u64) -> Result<(u64, Arc<Mutex<S>>)> {
        self.surfaces
            .get(&id)
            .cloned()
            .ok_or_else(|| self.missing(id, Kind::Surface))
    }

    pub fn remove_context(&mut self, id: u64) -> Result<Arc<Mutex<C>>> {
        match self.contexts.remove(&id) {
            Some(c) => Ok(c),
            None => Err(self.missing(id, Kind::Context)),
        }
    }

    pub fn remove_surface(&mut self, id: u64) -> Result<Arc<Mutex<S>>> {
        match self.surfaces.remove(&id) {
            Some((_, s)) => Ok(s),
            None => Err(self.missing(id, Kind::Surface)),
        }
    }

    /// Removes every surface of `context` (at its destruction), returning their states.
    pub fn remove_surfaces_of(&mut self, context: u64) -> Vec<Arc<Mutex<S>>> {
        let ids: Vec<u64> = self
            .surfaces
            .iter()
            .filter(|(_, (c, _))| *c == context)
            .map(|(id, _)| *id)
            .collect();
        ids.iter()
            .filter_map(|id| self.surfaces.remove(id).map(|(_, s)| s))
            .collect()
    }
}

/// Locks a handle's state; a lock poisoned by a panic on another thread is a typed error.
pub(crate) fn lock<T>(m: &Mutex<T>) -> Result<MutexGuard<'_, T>> {
    m.lock().map_err(|_| {
        Error::new(
            TesseraStatus::Internal,
            "the handle's lock was poisoned by an earlier panic",
        )
    })
}
