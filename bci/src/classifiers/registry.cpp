// The classifiers a session or `arbci train` can use, by name. A new method is a file in this
// folder that defines its Entry, and its line here.
#include "arbci/bci/classifier.h"

namespace arbci::bci {

ClassifierRegistry::Entry swldaClassifier();
ClassifierRegistry::Entry shrinkageLdaClassifier();
ClassifierRegistry::Entry xdawnClassifier();
ClassifierRegistry::Entry riemannClassifier();
ClassifierRegistry::Entry plainLdaClassifier();
ClassifierRegistry::Entry shiftLdaClassifier();

const ClassifierRegistry& classifiers() {
  static const ClassifierRegistry registry = [] {
    ClassifierRegistry r("classifier", "classifier.method");
    r.add(swldaClassifier());
    r.add(shrinkageLdaClassifier());
    r.add(xdawnClassifier());
    r.add(riemannClassifier());
    r.add(plainLdaClassifier());
    r.add(shiftLdaClassifier());
    return r;
  }();
  return registry;
}

}  // namespace arbci::bci
