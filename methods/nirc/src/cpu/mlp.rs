//! CPU reference of the tiny MLP: forward with ReLU hidden layers and a linear output, and the
//! backward pass (gradients of weights and of the encoded input).

use super::real::Real;
use crate::layout::ParameterLayout;

/// Everything the backward pass needs from the forward pass.
#[derive(Clone, Debug)]
pub struct Activations<T> {
    /// layers[0] = network input, layers[k] = output of hidden layer k after ReLU (k = 1..=H).
    pub layers: Vec<Vec<T>>,
    pub output: [T; 3],
}

pub fn forward<T: Real>(layout: &ParameterLayout, params: &[T], input: Vec<T>) -> Activations<T> {
    let hidden = layout.hidden_layers as usize;
    let mut layers = vec![input];
    let mut output = [T::zero(); 3];
    for (k, m) in layout.matrices.iter().enumerate() {
        let a = &layers[k];
        let mut z = vec![T::zero(); m.rows as usize];
        for (i, zi) in z.iter_mut().enumerate() {
            let row = m.offset as usize + i * m.cols as usize;
            let mut acc = T::zero();
            for (j, &aj) in a.iter().enumerate() {
                acc += params[row + j] * aj;
            }
            *zi = acc;
        }
        if k < hidden {
            for v in &mut z {
                if !(*v > T::zero()) {
                    *v = T::zero();
                }
            }
            layers.push(z);
        } else {
            output = [z[0], z[1], z[2]];
        }
    }
    Activations { layers, output }
}

/// Back-propagates dL/d(output). Returns the gradient of the pre-activation of every layer
/// (deltas[k] belongs to matrix k: hidden layers first, the output last) and dL/d(input).
/// The weight gradient of matrix k is deltas[k][i] * acts.layers[k][j].
pub fn backward<T: Real>(
    layout: &ParameterLayout,
    params: &[T],
    acts: &Activations<T>,
    d_output: [T; 3],
) -> (Vec<Vec<T>>, Vec<T>) {
    let n = layout.matrices.len();
    let mut deltas: Vec<Vec<T>> = vec![Vec::new(); n];
    deltas[n - 1] = d_output.to_vec();
    let mut d_input = Vec::new();
    for k in (0..n).rev() {
        let m = layout.matrices[k];
        let mut g = vec![T::zero(); m.cols as usize];
        for (j, gj) in g.iter_mut().enumerate() {
            let mut acc = T::zero();
            for i in 0..m.rows as usize {
                acc += params[m.offset as usize + i * m.cols as usize + j] * deltas[k][i];
            }
            *gj = acc;
        }
        if k == 0 {
            d_input = g;
        } else {
            // ReLU passes the gradient where its output was positive.
            for (j, gj) in g.iter_mut().enumerate() {
                if !(acts.layers[k][j] > T::zero()) {
                    *gj = T::zero();
                }
            }
            deltas[k - 1] = g;
        }
    }
    (deltas, d_input)
}
