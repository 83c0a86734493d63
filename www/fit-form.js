// @ts-check
// The fit options form: reads the options object (the core's FitSpec) from the form and shows
// the controls that apply to the chosen scheme, with the core's defaults. Every default and
// every rule of which option applies where comes from the package (defaultSpec, optionsFor,
// methodsFor, exportsFor); this module only knows the form's controls. A control names the
// FitSpec field it edits with `name`, and the label around it with `data-option`.
import { defaultSpec, exportsFor, methodsFor, optionsFor } from '../pkg/geofit.js';

/** How each method is offered in the method list (presentation only). */
const METHOD_LABELS = {
  geometric: 'error vectors (geometric)',
  'least-squares': 'least squares',
  knots: 'knot placement (least squares)',
  sections: 'sections (skinning of gridded rows)',
};

/** The placeholder of a field whose default the data decides. */
const FROM_DATA = 'automatic';

export class FitForm {
  /** @param {HTMLFormElement} form */
  constructor(form) {
    this.form = form;
    /** @type {HTMLSelectElement} */
    this.scheme = /** @type {any} */ (form.elements.namedItem('scheme'));
    /** @type {HTMLSelectElement} */
    this.method = /** @type {any} */ (form.elements.namedItem('method'));
    // Fields the user (or a sample's preset) set: a change of scheme keeps them.
    /** @type {Set<string>} */
    this.edited = new Set();
    // Of those, the ones a preset set and the user has not touched since: the next file
    // (a dropped one has no preset) gets the core's defaults there again.
    /** @type {Set<string>} */
    this.preset = new Set();
    for (const control of this.controls()) {
      control.addEventListener('input', () => {
        this.edited.add(control.name);
        this.preset.delete(control.name);
      });
    }
    this.scheme.addEventListener('input', () => this.preset.delete('scheme'));
    this.schemeChanged();
  }

  /** The controls that edit a FitSpec field (the scheme list aside). */
  controls() {
    return /** @type {(HTMLInputElement | HTMLSelectElement)[]} */ (
      [...this.form.querySelectorAll('input[name], select[name]')].filter((c) => c.getAttribute('name') !== 'scheme')
    );
  }

  /** The options of the chosen scheme and method. */
  applicable() {
    return new Set(/** @type {string[]} */ (optionsFor(this.scheme.value, this.method.value || undefined)));
  }

  /**
   * After a change of scheme: the method list of the scheme, the controls that apply, and the
   * core's defaults in every field the user did not set.
   */
  schemeChanged() {
    const scheme = this.scheme.value;
    const methods = /** @type {string[]} */ (methodsFor(scheme));
    const keep = methods.includes(this.method.value) && this.edited.has('method') ? this.method.value : methods[0];
    this.method.replaceChildren(...methods.map((m) => new Option(METHOD_LABELS[m] ?? m, m)));
    this.method.value = keep;
    this.showDefaults();
  }

  /** Shows the controls of the scheme and method, with the defaults where nothing was set. */
  showDefaults() {
    const applies = this.applicable();
    for (const label of this.form.querySelectorAll('[data-option]')) {
      /** @type {HTMLElement} */ (label).hidden = !applies.has(/** @type {HTMLElement} */ (label).dataset.option ?? '');
    }
    const defaults = defaultSpec(this.scheme.value, this.method.value || undefined);
    for (const control of this.controls()) {
      if (this.edited.has(control.name) || control.name === 'method') continue;
      // A list with an empty choice offers "the core's default", which may depend on other
      // fields (the acceleration on the weights): leave it to the core.
      const coreDecides = control instanceof HTMLSelectElement && [...control.options].some((o) => o.value === '');
      setValue(control, coreDecides ? '' : defaults[control.name]);
    }
    for (const button of document.querySelectorAll('[data-export]')) {
      /** @type {HTMLButtonElement} */ (button).disabled = !this.exports().includes(/** @type {HTMLElement} */ (button).dataset.export ?? '');
    }
  }

  /** The exports the chosen scheme offers. */
  exports() {
    return /** @type {string[]} */ (exportsFor(this.scheme.value));
  }

  /**
   * Sets fields from a file's preset (a bundled sample's options object; `{}` for a file of
   * the user's), as if the user had. What an earlier preset set and the user left alone goes
   * back to the core's default (the scheme to the page's first); what the user set stays.
   * @param {Object<string, unknown>} preset
   */
  apply(preset) {
    for (const name of this.preset) this.edited.delete(name);
    if (this.preset.has('scheme')) this.scheme.value = this.scheme.options[0].value;
    this.preset.clear();
    if (typeof preset.scheme === 'string') {
      this.scheme.value = preset.scheme;
      this.preset.add('scheme');
    }
    this.schemeChanged();
    for (const control of this.controls()) {
      if (control.name in preset) {
        setValue(control, preset[control.name]);
        this.edited.add(control.name);
        this.preset.add(control.name);
      }
    }
  }

  /** The options object for `new Fitter(scan, spec)`: the scheme and every applicable field with a value. */
  spec() {
    const applies = this.applicable();
    /** @type {Object<string, unknown>} */
    const spec = { scheme: this.scheme.value };
    for (const control of this.controls()) {
      if (!applies.has(control.name)) continue;
      const value = readValue(control);
      if (value !== undefined) spec[control.name] = value;
    }
    return spec;
  }
}

/**
 * A control's value as the options object wants it: numbers, booleans, names; `undefined` for
 * an empty field (the core's default, or the data's).
 * @param {HTMLInputElement | HTMLSelectElement} control
 */
function readValue(control) {
  if (control instanceof HTMLInputElement && control.type === 'checkbox') return control.checked;
  const text = control.value.trim();
  if (text === '') return undefined;
  return control instanceof HTMLInputElement && control.type === 'number' ? Number(text) : text;
}

/**
 * Shows `value` (a default or a preset) in a control; `null` leaves it empty with a note that
 * the data decides.
 * @param {HTMLInputElement | HTMLSelectElement} control
 * @param {unknown} value
 */
function setValue(control, value) {
  if (control instanceof HTMLInputElement && control.type === 'checkbox') {
    control.checked = Boolean(value);
    return;
  }
  control.value = value === null || value === undefined ? '' : String(value);
  if (control instanceof HTMLInputElement) control.placeholder = value === null || value === undefined ? FROM_DATA : '';
}
