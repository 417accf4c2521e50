//! Local variables stored once: loads after the store can read the
//! variable's cells in place instead of copying them.
//!
//! naga's GLSL front end turns every `float x = …;` and every argument into
//! a local variable with one store and many loads; reading those in place
//! removes most of the copies a GLSL BRDF runs. A load is read in place only
//! when that is unobservable: the variable is stored exactly once, by a
//! whole-variable store that is a statement of the function body itself (so
//! it runs once, and everything emitted in later body statements runs after
//! it), no pointer to it escapes into a call or a partial store, and the load
//! is emitted in a later body statement.

use naga::{Block, Expression, Function, Handle, Statement};

/// What the analysis found for one function.
pub(super) struct SingleStore {
    /// Per local variable: the index of the body statement holding its only
    /// store, when it qualifies.
    store_at: Vec<Option<usize>>,
    /// Per expression: the index of the body statement whose code emits it.
    emitted_at: Vec<usize>,
}

/// The local variable a pointer expression is rooted at, and whether it is
/// the whole variable.
fn root(fun: &Function, mut h: Handle<Expression>) -> Option<(usize, bool)> {
    let mut whole = true;
    loop {
        match fun.expressions[h] {
            Expression::LocalVariable(l) => return Some((l.index(), whole)),
            Expression::Access { base, .. } | Expression::AccessIndex { base, .. } => {
                whole = false;
                h = base;
            }
            _ => return None,
        }
    }
}

impl SingleStore {
    /// Analyses `fun`.
    pub(super) fn new(fun: &Function) -> SingleStore {
        let nl = fun.local_variables.len();
        let mut stores: Vec<Vec<usize>> = vec![Vec::new(); nl];
        let mut escapes = vec![false; nl];
        let mut emitted_at = vec![usize::MAX; fun.expressions.len()];
        for (top, s) in fun.body.iter().enumerate() {
            visit(
                fun,
                s,
                top,
                true,
                &mut stores,
                &mut escapes,
                &mut emitted_at,
            );
        }
        let store_at = stores
            .iter()
            .zip(&escapes)
            .map(|(s, &e)| if !e && s.len() == 1 { Some(s[0]) } else { None })
            .collect();
        SingleStore {
            store_at,
            emitted_at,
        }
    }

    /// Whether the load `load` of `pointer` may read the variable in place.
    pub(super) fn in_place(
        &self,
        fun: &Function,
        pointer: Handle<Expression>,
        load: Handle<Expression>,
    ) -> bool {
        let Some((v, _)) = root(fun, pointer) else {
            return false;
        };
        match (self.store_at.get(v), self.emitted_at.get(load.index())) {
            (Some(&Some(s)), Some(&at)) => at != usize::MAX && at > s,
            _ => false,
        }
    }
}

fn visit_block(
    fun: &Function,
    b: &Block,
    top: usize,
    stores: &mut Vec<Vec<usize>>,
    escapes: &mut [bool],
    emitted_at: &mut [usize],
) {
    for s in b.iter() {
        visit(fun, s, top, false, stores, escapes, emitted_at);
    }
}

fn visit(
    fun: &Function,
    s: &Statement,
    top: usize,
    at_top: bool,
    stores: &mut Vec<Vec<usize>>,
    escapes: &mut [bool],
    emitted_at: &mut [usize],
) {
    match *s {
        Statement::Emit(ref r) => {
            for i in r.index_range() {
                if let Some(e) = emitted_at.get_mut(i as usize) {
                    *e = top;
                }
            }
        }
        Statement::Store { pointer, .. } => {
            if let Some((v, whole)) = root(fun, pointer) {
                if whole && at_top {
                    stores[v].push(top);
                } else {
                    escapes[v] = true;
                }
            }
        }
        Statement::Call { ref arguments, .. } => {
            for &a in arguments {
                if let Some((v, _)) = root(fun, a) {
                    escapes[v] = true;
                }
            }
        }
        Statement::Block(ref b) => visit_block(fun, b, top, stores, escapes, emitted_at),
        Statement::If {
            ref accept,
            ref reject,
            ..
        } => {
            visit_block(fun, accept, top, stores, escapes, emitted_at);
            visit_block(fun, reject, top, stores, escapes, emitted_at);
        }
        Statement::Switch { ref cases, .. } => {
            for c in cases {
                visit_block(fun, &c.body, top, stores, escapes, emitted_at);
            }
        }
        Statement::Loop {
            ref body,
            ref continuing,
            ..
        } => {
            visit_block(fun, body, top, stores, escapes, emitted_at);
            visit_block(fun, continuing, top, stores, escapes, emitted_at);
        }
        // Everything else that takes a pointer (atomics, image stores, …) is
        // refused by the compiler anyway.
        _ => {}
    }
}
